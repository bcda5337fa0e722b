#include "viscera/mcap/mcap_writer.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <sys/stat.h>
#include <unistd.h>

#include <fcntl.h>

#include "viscera/mcap/compression.hpp"

namespace viscera::mcap {

namespace {
std::uint8_t op(Opcode o) { return static_cast<std::uint8_t>(o); }
}  // namespace

McapWriter::McapWriter(const std::string& path, WriterOptions options) : path_(path), options_(std::move(options)) {
  if (!options_.compression.empty() && options_.compression != "zstd" && options_.compression != "lz4")
    throw std::invalid_argument("compression '" + options_.compression + "' is not zstd, lz4 or none");
  // O_NOFOLLOW: a link planted at the path (a shared folder, /tmp) is not written through, whoever
  // runs this; O_EXCL: an earlier recording is not replaced unless asked.
  // O_NONBLOCK: a FIFO at the path fails or opens at once instead of blocking, and is refused below.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK | (options_.replace ? O_TRUNC : O_EXCL), 0644);
  if (fd < 0) {
    const int e = errno;
    struct stat st {};
    if (e == ELOOP || (::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode)))
      throw std::runtime_error(path + ": is a symbolic link: not written through (name the file itself)");
    if (e == EEXIST)
      throw std::runtime_error(path + ": exists, and is not replaced: a recording is never lost to the next one (choose another name, or remove it)");
    if (e == ENXIO) throw std::runtime_error(path + ": is not a regular file (a FIFO): a recording is written to a file");
    throw std::runtime_error(path + ": cannot create the file: " + std::strerror(e));
  }
  if (struct stat st{}; ::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw std::runtime_error(path + ": is not a regular file: a recording is written to a file");
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  file_ = std::unique_ptr<std::FILE, CloseFile>(::fdopen(fd, "wb"));
  if (!file_) {
    ::close(fd);
    throw std::runtime_error(path + ": cannot create the file");
  }
  ByteWriter w;
  w.raw(kMagic);
  const auto at = w.begin_record(op(Opcode::header));
  w.string(options_.profile);
  w.string(options_.library);
  w.end_record(at);
  write(w.bytes());
  std::fflush(file_.get());
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {
    // a destructor must not throw; close() explicitly to see errors
  }
}

void McapWriter::write(const std::vector<std::uint8_t>& bytes, bool data_section) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) != bytes.size()) throw std::runtime_error(path_ + ": write failed (disk full?)");
  if (data_section) data_crc_ = crc32_update(data_crc_, bytes.data(), bytes.size());
  position_ += bytes.size();
}

void McapWriter::schema_record(ByteWriter& w, const Schema& s) const {
  const auto at = w.begin_record(op(Opcode::schema));
  w.u16(s.id);
  w.string(s.name);
  w.string(s.encoding);
  w.bytes32(s.data);
  w.end_record(at);
}

void McapWriter::channel_record(ByteWriter& w, const Channel& c) const {
  const auto at = w.begin_record(op(Opcode::channel));
  w.u16(c.id);
  w.u16(c.schema_id);
  w.string(c.topic);
  w.string(c.message_encoding);
  w.string_map(c.metadata);
  w.end_record(at);
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, std::vector<std::uint8_t> data) {
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);  // 0 means "no schema"
  schemas_[id] = {id, name, encoding, std::move(data)};
  schema_in_file_.resize(id + 1, false);
  ++stats_.schema_count;
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                                      std::map<std::string, std::string> metadata) {
  if (schema_id != 0 && !schemas_.count(schema_id)) throw std::invalid_argument("add_channel: no schema " + std::to_string(schema_id));
  const auto id = static_cast<std::uint16_t>(channels_.size());
  channels_[id] = {id, schema_id, topic, message_encoding, std::move(metadata)};
  channel_in_file_.resize(id + 1, false);
  ++stats_.channel_count;
  return id;
}

void McapWriter::add_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time, std::uint64_t publish_time,
                             std::span<const std::uint8_t> data) {
  const auto c = channels_.find(channel_id);
  if (c == channels_.end()) throw std::invalid_argument("add_message: no channel " + std::to_string(channel_id));
  if (!channel_in_file_[channel_id]) {  // its schema and itself into this chunk, before its first message
    if (c->second.schema_id != 0 && !schema_in_file_[c->second.schema_id]) {
      schema_record(chunk_, schemas_.at(c->second.schema_id));
      schema_in_file_[c->second.schema_id] = true;
    }
    channel_record(chunk_, c->second);
    channel_in_file_[channel_id] = true;
  }
  chunk_index_[channel_id].emplace_back(log_time, chunk_.bytes().size());
  const auto at = chunk_.begin_record(op(Opcode::message));
  chunk_.u16(channel_id);
  chunk_.u32(sequence);
  chunk_.u64(log_time);
  chunk_.u64(publish_time);
  chunk_.raw(data);
  chunk_.end_record(at);
  chunk_start_ = chunk_start_ ? std::min(*chunk_start_, log_time) : log_time;
  chunk_end_ = chunk_end_ ? std::max(*chunk_end_, log_time) : log_time;
  stats_.message_start_time = stats_.message_count == 0 ? log_time : std::min(stats_.message_start_time, log_time);
  stats_.message_end_time = std::max(stats_.message_end_time, log_time);
  ++stats_.message_count;
  ++stats_.channel_message_counts[channel_id];
  if (chunk_.bytes().size() >= options_.chunk_bytes || *chunk_end_ - *chunk_start_ >= options_.chunk_ns) close_chunk();
}

void McapWriter::flush_if_due(std::uint64_t now_log_time) {
  if (chunk_start_ && now_log_time >= *chunk_start_ + options_.chunk_ns) close_chunk();
}

void McapWriter::close_chunk() {
  if (chunk_.bytes().empty()) return;
  const std::vector<std::uint8_t>& records = chunk_.bytes();
  const std::vector<std::uint8_t> compressed = compress(options_.compression, records);
  ByteWriter w;
  const auto at = w.begin_record(op(Opcode::chunk));
  w.u64(chunk_start_.value_or(0));
  w.u64(chunk_end_.value_or(0));
  w.u64(records.size());
  w.u32(crc32(records.data(), records.size()));
  w.string(options_.compression);
  w.u64(compressed.size());
  w.raw(compressed);
  w.end_record(at);
  ChunkIndexEntry entry{chunk_start_.value_or(0), chunk_end_.value_or(0), position_, w.bytes().size(), {}, 0, compressed.size(), records.size()};
  write(w.bytes());
  ByteWriter index;
  for (const auto& [channel, entries] : chunk_index_) {
    entry.message_index_offsets[channel] = position_ + index.bytes().size();
    const auto mi = index.begin_record(op(Opcode::message_index));
    index.u16(channel);
    const auto list = index.reserve32();
    for (const auto& [time, offset] : entries) {
      index.u64(time);
      index.u64(offset);
    }
    index.patch32(list);
    index.end_record(mi);
  }
  entry.message_index_length = index.bytes().size();
  write(index.bytes());
  std::fflush(file_.get());
  chunk_indexes_.push_back(std::move(entry));
  ++stats_.chunk_count;
  chunk_.clear();
  chunk_index_.clear();
  chunk_start_.reset();
  chunk_end_.reset();
}

void McapWriter::add_attachment(const Attachment& a) {
  ByteWriter w;
  const auto at = w.begin_record(op(Opcode::attachment));
  w.u64(a.log_time);
  w.u64(a.create_time);
  w.string(a.name);
  w.string(a.media_type);
  w.u64(a.data.size());
  w.raw(a.data);
  w.u32(crc32(w.bytes().data() + at, w.bytes().size() - at));  // of every field before it
  w.end_record(at);
  ByteWriter index;
  const auto ia = index.begin_record(op(Opcode::attachment_index));
  index.u64(position_);
  index.u64(w.bytes().size());
  index.u64(a.log_time);
  index.u64(a.create_time);
  index.u64(a.data.size());
  index.string(a.name);
  index.string(a.media_type);
  index.end_record(ia);
  write(w.bytes());
  std::fflush(file_.get());
  attachment_indexes_.push_back(std::move(index.bytes()));
  ++stats_.attachment_count;
}

void McapWriter::add_metadata(const Metadata& m) {
  ByteWriter w;
  const auto at = w.begin_record(op(Opcode::metadata));
  w.string(m.name);
  w.string_map(m.values);
  w.end_record(at);
  ByteWriter index;
  const auto ia = index.begin_record(op(Opcode::metadata_index));
  index.u64(position_);
  index.u64(w.bytes().size());
  index.string(m.name);
  index.end_record(ia);
  write(w.bytes());
  std::fflush(file_.get());
  metadata_indexes_.push_back(std::move(index.bytes()));
  ++stats_.metadata_count;
}

void McapWriter::close() {
  if (closed_ || !file_) return;
  closed_ = true;
  close_chunk();
  ByteWriter end;
  const auto de = end.begin_record(op(Opcode::data_end));
  end.u32(crc32_final(data_crc_));
  end.end_record(de);
  write(end.bytes(), false);

  // The summary: each group of records, and where it starts (the summary offsets).
  const std::uint64_t summary_start = position_;
  std::uint32_t summary_crc = kCrc32Init;
  std::vector<std::tuple<Opcode, std::uint64_t, std::uint64_t>> groups;
  const auto group = [&](Opcode opcode, const std::vector<std::uint8_t>& bytes) {
    if (bytes.empty()) return;
    groups.emplace_back(opcode, position_, bytes.size());
    summary_crc = crc32_update(summary_crc, bytes.data(), bytes.size());
    write(bytes, false);
  };
  ByteWriter schemas, channels, statistics, metadata, attachments, chunks;
  for (const auto& [id, s] : schemas_) schema_record(schemas, s);
  for (const auto& [id, c] : channels_) channel_record(channels, c);
  const auto st = statistics.begin_record(op(Opcode::statistics));
  statistics.u64(stats_.message_count);
  statistics.u16(stats_.schema_count);
  statistics.u32(stats_.channel_count);
  statistics.u32(stats_.attachment_count);
  statistics.u32(stats_.metadata_count);
  statistics.u32(stats_.chunk_count);
  statistics.u64(stats_.message_start_time);
  statistics.u64(stats_.message_end_time);
  const auto counts = statistics.reserve32();
  for (const auto& [channel, n] : stats_.channel_message_counts) {
    statistics.u16(channel);
    statistics.u64(n);
  }
  statistics.patch32(counts);
  statistics.end_record(st);
  for (const auto& m : metadata_indexes_) metadata.raw(m);
  for (const auto& a : attachment_indexes_) attachments.raw(a);
  for (const auto& c : chunk_indexes_) {
    const auto ci = chunks.begin_record(op(Opcode::chunk_index));
    chunks.u64(c.start_time);
    chunks.u64(c.end_time);
    chunks.u64(c.offset);
    chunks.u64(c.length);
    const auto offsets = chunks.reserve32();
    for (const auto& [channel, offset] : c.message_index_offsets) {
      chunks.u16(channel);
      chunks.u64(offset);
    }
    chunks.patch32(offsets);
    chunks.u64(c.message_index_length);
    chunks.string(options_.compression);
    chunks.u64(c.compressed_size);
    chunks.u64(c.uncompressed_size);
    chunks.end_record(ci);
  }
  group(Opcode::schema, schemas.bytes());
  group(Opcode::channel, channels.bytes());
  group(Opcode::statistics, statistics.bytes());
  group(Opcode::metadata_index, metadata.bytes());
  group(Opcode::attachment_index, attachments.bytes());
  group(Opcode::chunk_index, chunks.bytes());
  const std::uint64_t summary_offset_start = position_;
  ByteWriter offsets;
  for (const auto& [opcode, start, length] : groups) {
    const auto so = offsets.begin_record(op(Opcode::summary_offset));
    offsets.u8(op(opcode));
    offsets.u64(start);
    offsets.u64(length);
    offsets.end_record(so);
  }
  summary_crc = crc32_update(summary_crc, offsets.bytes().data(), offsets.bytes().size());
  write(offsets.bytes(), false);
  ByteWriter footer;
  footer.u8(op(Opcode::footer));
  footer.u64(8 + 8 + 4);  // the footer's fixed length
  footer.u64(summary_start);
  footer.u64(summary_offset_start);
  summary_crc = crc32_update(summary_crc, footer.bytes().data(), footer.bytes().size());  // through summary_offset_start
  footer.u32(crc32_final(summary_crc));
  footer.raw(kMagic);
  write(footer.bytes(), false);
  const bool flushed = std::fflush(file_.get()) == 0;
  file_.reset();
  if (!flushed) throw std::runtime_error(path_ + ": cannot write the file's end (disk full?)");
}

}  // namespace viscera::mcap
