#include "viscera/mcap/mcap_reader.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <map>

#include <sys/stat.h>

#include "viscera/common/input_error.hpp"
#include "viscera/mcap/byte_codec.hpp"
#include "viscera/mcap/compression.hpp"

namespace viscera::mcap {

/// Known schemas and channels while reading: a message needs its channel, a channel its schema.
struct detail::Registry {
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  void schema(const Schema& s, const DataVisitor& v) {
    if (s.id == 0) throw FormatError("schema with id 0 (reserved for \"no schema\")");
    const auto [it, fresh] = schemas.emplace(s.id, s);
    if (!fresh && (it->second.name != s.name || it->second.data != s.data))
      throw FormatError("schema " + std::to_string(s.id) + " given twice, differently");
    if (fresh && v.schema) v.schema(s);
  }
  void channel(const Channel& c, const DataVisitor& v) {
    if (c.schema_id != 0 && !schemas.count(c.schema_id))
      throw FormatError("channel " + std::to_string(c.id) + " (" + c.topic + ") names schema " + std::to_string(c.schema_id) +
                        ", which has not appeared");
    const auto [it, fresh] = channels.emplace(c.id, c);
    if (!fresh && (it->second.topic != c.topic || it->second.schema_id != c.schema_id))
      throw FormatError("channel " + std::to_string(c.id) + " given twice, differently");
    if (fresh && v.channel) v.channel(c);
  }
  void message(const Message& m) const {
    if (!channels.count(m.channel_id)) throw FormatError("message on channel " + std::to_string(m.channel_id) + ", which has not appeared");
  }
};

namespace {

using detail::Registry;

Schema parse_schema(ByteReader& r) {
  Schema s;
  s.id = r.u16();
  s.name = r.string();
  s.encoding = r.string();
  s.data = r.bytes32();
  return s;
}

Channel parse_channel(ByteReader& r) {
  Channel c;
  c.id = r.u16();
  c.schema_id = r.u16();
  c.topic = r.string();
  c.message_encoding = r.string();
  c.metadata = r.string_map();
  return c;
}

Message parse_message(ByteReader& r) {
  Message m;
  m.channel_id = r.u16();
  m.sequence = r.u32();
  m.log_time = r.u64();
  m.publish_time = r.u64();
  const auto rest = r.rest();
  m.data.assign(rest.begin(), rest.end());
  return m;
}

/// A Chunk record's messages, its records checked against its CRC; its schemas and channels go
/// into `known`.
std::vector<Message> chunk_messages(ByteReader& r, Registry& known) {
  r.u64();  // message start time
  r.u64();  // message end time
  const std::uint64_t size = r.u64();
  const std::uint32_t crc = r.u32();
  const std::string compression = r.string();
  const auto compressed = r.raw(r.u64());
  const std::vector<std::uint8_t> records = decompress(compression, compressed, size);
  if (crc != 0 && crc32(records.data(), records.size()) != crc) throw FormatError("chunk: the CRC of its records does not match (damaged)");
  std::vector<Message> messages;
  ByteReader c(records);
  while (c.left() > 0) {
    const auto op = static_cast<Opcode>(c.u8());
    ByteReader rr(c.raw(c.u64()));
    if (op == Opcode::schema)
      known.schema(parse_schema(rr), {});
    else if (op == Opcode::channel)
      known.channel(parse_channel(rr), {});
    else if (op == Opcode::message) {
      messages.push_back(parse_message(rr));
      known.message(messages.back());
    }
  }
  return messages;
}

/// `content`: the whole record, for its CRC.
Attachment parse_attachment(ByteReader& r, std::span<const std::uint8_t> content) {
  Attachment a;
  a.log_time = r.u64();
  a.create_time = r.u64();
  a.name = r.string();
  a.media_type = r.string();
  const auto data = r.raw(r.u64());
  a.data.assign(data.begin(), data.end());
  const std::size_t covered = r.position();
  const std::uint32_t crc = r.u32();
  if (crc != 0 && crc32(content.data(), covered) != crc) throw FormatError("attachment " + a.name + ": its CRC does not match (damaged)");
  return a;
}

Metadata parse_metadata(ByteReader& r) {
  Metadata m;
  m.name = r.string();
  m.values = r.string_map();
  return m;
}

}  // namespace

McapReader::McapReader(const std::string& path) : path_(path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw common::InputError(path, 0, "", "cannot open file");
  if (!S_ISREG(st.st_mode)) throw common::InputError(path, 0, "", "is not a regular file");
  size_ = static_cast<std::uint64_t>(st.st_size);
  in_.open(path, std::ios::binary);
  if (!in_) throw common::InputError(path, 0, "", "cannot open file");
  if (size_ < kMagic.size() + 9) fail(0, "not an MCAP file: " + std::to_string(size_) + " bytes");
  const auto magic = read_at(0, kMagic.size());
  if (!std::equal(magic.begin(), magic.end(), kMagic.begin())) fail(0, "not an MCAP file (no MCAP magic at its start)");
  const auto head = read_at(kMagic.size(), 9);
  ByteReader h(head);
  if (h.u8() != static_cast<std::uint8_t>(Opcode::header)) fail(kMagic.size(), "the first record is not a Header");
  const std::uint64_t n = h.u64();
  if (n > size_ - kMagic.size() - 9) fail(kMagic.size(), "the Header's length " + std::to_string(n) + " runs past the end of the file");
  try {
    const auto content = read_at(kMagic.size() + 9, n);
    ByteReader r(content);
    profile_ = r.string();
    library_ = r.string();
  } catch (const FormatError& e) {
    fail(kMagic.size(), std::string("Header: ") + e.what());
  }
  data_start_ = kMagic.size() + 9 + n;
}

void McapReader::fail(std::uint64_t offset, const std::string& what) const {
  throw common::InputError(path_, 0, "byte " + std::to_string(offset), what);
}

std::vector<std::uint8_t> McapReader::read_at(std::uint64_t offset, std::uint64_t n) {
  if (offset > size_ || n > size_ - offset)
    fail(offset, "a read of " + std::to_string(n) + " bytes runs past the end of the file (" + std::to_string(size_) + " bytes)");
  constexpr std::uint64_t kBlock = 1 << 20;
  const auto from_window = [&] {
    const auto first = window_.begin() + static_cast<std::ptrdiff_t>(offset - window_start_);
    return std::vector<std::uint8_t>(first, first + static_cast<std::ptrdiff_t>(n));
  };
  if (offset >= window_start_ && offset + n <= window_start_ + window_.size()) return from_window();
  const std::uint64_t want = n >= kBlock ? n : std::min(kBlock, size_ - offset);  // a large read goes straight through
  std::vector<std::uint8_t> b(static_cast<std::size_t>(want));
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(offset));
  in_.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(want));
  if (static_cast<std::uint64_t>(in_.gcount()) != want) fail(offset, "cannot read the file");
  if (want == n) return b;
  window_ = std::move(b);
  window_start_ = offset;
  return from_window();
}

std::uint64_t McapReader::read_record(std::uint64_t at, Registry& known, const DataVisitor& visit, DataEnd& end) {
  if (size_ - at < 9) throw FormatError("the file ends inside a record's opcode and length (cut short?)");
  const auto head = read_at(at, 9);
  ByteReader h(head);
  const auto opcode = static_cast<Opcode>(h.u8());
  const std::uint64_t n = h.u64();
  if (n > size_ - at - 9) throw FormatError("a record of " + std::to_string(n) + " bytes runs past the end of the file (cut short?)");
  const auto content = read_at(at + 9, n);
  ByteReader r(content);
  switch (opcode) {
    case Opcode::data_end: end.complete = true; break;
    case Opcode::schema: known.schema(parse_schema(r), visit); break;
    case Opcode::channel: known.channel(parse_channel(r), visit); break;
    case Opcode::message: {
      const Message m = parse_message(r);
      known.message(m);
      if (visit.message) visit.message(m);
      ++end.messages;
      break;
    }
    case Opcode::chunk: {
      // The whole chunk first: a chunk whose records do not all parse gives nothing.
      Registry inner = known;
      const std::vector<Message> messages = chunk_messages(r, inner);
      for (const auto& [id, sch] : inner.schemas)
        if (!known.schemas.count(id)) known.schema(sch, visit);
      for (const auto& [id, ch] : inner.channels)
        if (!known.channels.count(id)) known.channel(ch, visit);
      for (const Message& m : messages)
        if (visit.message) visit.message(m);
      end.messages += messages.size();
      ++end.chunks;
      break;
    }
    case Opcode::attachment: {
      const Attachment a = parse_attachment(r, content);
      if (visit.attachment) visit.attachment(a);
      ++end.attachments;
      break;
    }
    case Opcode::metadata: {
      const Metadata m = parse_metadata(r);
      if (visit.metadata) visit.metadata(m);
      break;
    }
    case Opcode::header:
    case Opcode::footer: throw FormatError("a Header or Footer inside the data section");
    default:
      // Opcode 0 is reserved by the specification: no writer makes it (zeros are space a crash
      // left unwritten). Message indexes and records this reader does not use are skipped.
      if (static_cast<std::uint8_t>(opcode) == 0) throw FormatError("opcode 0 is not a record (zero bytes: never written?)");
      break;
  }
  return 9 + n;
}

DataEnd McapReader::read_data(const DataVisitor& visit) {
  DataEnd end;
  Registry known;
  std::uint64_t at = data_start_;
  while (!end.complete) {
    end.offset = at;
    try {
      at += read_record(at, known, visit, end);
    } catch (const FormatError& e) {
      end.error = e.what();
      return end;
    } catch (const common::InputError& e) {
      end.error = e.what();
      return end;
    }
  }
  return end;
}

DataEnd McapReader::salvage_data(const DataVisitor& visit) {
  DataEnd end;
  Registry known;
  // The summary, where it reads, names every schema and channel: messages of a chunk that follows a
  // damaged one keep their channel.
  try {
    if (const auto s = summary()) {
      for (const auto& sch : s->schemas) known.schema(sch, visit);
      for (const auto& c : s->channels) known.channel(c, visit);
    }
  } catch (const common::InputError&) {  // a damaged summary: the data section alone
  } catch (const FormatError&) {
  }
  std::uint64_t at = data_start_;
  while (!end.complete) {
    end.offset = at;
    if (at == size_) {
      end.error = "the file ends after the record before byte " + std::to_string(at) + ", without Data End (cut short)";
      return end;
    }
    if (read_at(at, 1)[0] == 0 && zeros_to_end(at)) {
      end.error = "zero bytes from byte " + std::to_string(at) + " to the end (space a crash left unwritten)";
      end.damaged.push_back({at, size_ - at, std::to_string(size_ - at) + " zero bytes: nothing was written there"});
      return end;
    }
    try {
      at += read_record(at, known, visit, end);
    } catch (const std::exception& e) {  // FormatError or common::InputError: the record does not parse
      std::uint64_t next = size_;
      if (size_ - at >= 9) {
        const auto head = read_at(at, 9);
        ByteReader h(head);
        const std::uint8_t opcode = h.u8();
        const std::uint64_t n = h.u64();
        const bool framed = opcode >= 1 && opcode <= 0x0F && n <= size_ - at - 9;
        // A record whose length holds is skipped whole, unless what follows it does not start a
        // record (the length itself was damaged): then the walk resumes at the next record whose
        // CRC holds.
        next = framed && (at + 9 + n == size_ || checked_record_at(at + 9 + n) || read_at(at + 9 + n, 1)[0] <= 0x0F) ? at + 9 + n
                                                                                                                     : next_checked_record(at + 1);
      }
      end.error = e.what();
      end.damaged.push_back({at, next - at, e.what()});
      at = next;
      if (at == size_) return end;
    }
  }
  return end;
}

bool McapReader::checked_record_at(std::uint64_t at) {
  if (size_ - at < 9) return false;
  const auto head = read_at(at, 9);
  ByteReader h(head);
  const auto opcode = static_cast<Opcode>(h.u8());
  const std::uint64_t n = h.u64();
  if ((opcode != Opcode::chunk && opcode != Opcode::attachment && opcode != Opcode::data_end) || n > size_ - at - 9) return false;
  try {
    const auto content = read_at(at + 9, n);
    ByteReader r(content);
    if (opcode == Opcode::data_end) return n == 4;
    if (opcode == Opcode::attachment) {
      parse_attachment(r, content);
      return content.size() >= 4 &&
             (content[content.size() - 4] | content[content.size() - 3] | content[content.size() - 2] | content[content.size() - 1]) != 0;
    }
    // A chunk: its CRC must be given (not 0) and hold (its channels may be in earlier chunks).
    r.u64();
    r.u64();
    const std::uint64_t size = r.u64();
    const std::uint32_t crc = r.u32();
    const std::string compression = r.string();
    const auto records = decompress(compression, r.raw(r.u64()), size);
    return crc != 0 && crc32(records.data(), records.size()) == crc;
  } catch (const FormatError&) {
    return false;
  } catch (const common::InputError&) {
    return false;
  }
}

std::uint64_t McapReader::next_checked_record(std::uint64_t from) {
  constexpr std::uint64_t kWindow = 1 << 20;
  for (std::uint64_t base = from; base < size_; base += kWindow) {
    const auto window = read_at(base, std::min(kWindow, size_ - base));
    for (std::size_t k = 0; k < window.size(); ++k) {
      const auto op = static_cast<Opcode>(window[k]);
      if ((op == Opcode::chunk || op == Opcode::attachment || op == Opcode::data_end) && checked_record_at(base + k)) return base + k;
    }
  }
  return size_;
}

bool McapReader::zeros_to_end(std::uint64_t from) {
  constexpr std::uint64_t kWindow = 1 << 20;
  for (std::uint64_t base = from; base < size_; base += kWindow) {
    const auto window = read_at(base, std::min(kWindow, size_ - base));
    if (std::any_of(window.begin(), window.end(), [](std::uint8_t b) { return b != 0; })) return false;
  }
  return true;
}

std::optional<Summary> McapReader::summary() {
  const std::uint64_t footer_size = 1 + 8 + 20 + kMagic.size();
  if (size_ < data_start_ + footer_size) return std::nullopt;
  const auto tail = read_at(size_ - footer_size, footer_size);
  if (!std::equal(kMagic.begin(), kMagic.end(), tail.end() - kMagic.size()) || tail[0] != static_cast<std::uint8_t>(Opcode::footer))
    return std::nullopt;
  ByteReader f(tail);
  f.u8();
  if (f.u64() != 20) fail(size_ - footer_size, "Footer: length is not 20");
  const std::uint64_t summary_start = f.u64(), summary_offset_start = f.u64();
  const std::uint32_t summary_crc = f.u32();
  if (summary_start == 0) return Summary{};
  const std::uint64_t footer_at = size_ - footer_size;
  if (summary_start > footer_at || (summary_offset_start != 0 && (summary_offset_start < summary_start || summary_offset_start > footer_at)))
    fail(footer_at, "Footer: the summary offsets point outside the file");
  const auto summary = read_at(summary_start, footer_at - summary_start);
  if (summary_crc != 0) {
    std::uint32_t crc = crc32_update(kCrc32Init, summary.data(), summary.size());
    crc = crc32_update(crc, tail.data(), 1 + 8 + 16);
    if (crc32_final(crc) != summary_crc) fail(summary_start, "the summary's CRC does not match (damaged)");
  }
  Summary s;
  try {
    ByteReader r(std::span<const std::uint8_t>(summary).first(
        static_cast<std::size_t>((summary_offset_start ? summary_offset_start : footer_at) - summary_start)));
    while (r.left() > 0) {
      const auto opcode = static_cast<Opcode>(r.u8());
      ByteReader rr(r.raw(r.u64()));
      switch (opcode) {
        case Opcode::schema: s.schemas.push_back(parse_schema(rr)); break;
        case Opcode::channel: s.channels.push_back(parse_channel(rr)); break;
        case Opcode::statistics: {
          Statistics st;
          st.message_count = rr.u64();
          st.schema_count = rr.u16();
          st.channel_count = rr.u32();
          st.attachment_count = rr.u32();
          st.metadata_count = rr.u32();
          st.chunk_count = rr.u32();
          st.message_start_time = rr.u64();
          st.message_end_time = rr.u64();
          ByteReader counts(rr.raw(rr.u32()));
          while (counts.left() > 0) {
            const auto channel = counts.u16();
            st.channel_message_counts[channel] = counts.u64();
          }
          s.statistics = st;
          break;
        }
        case Opcode::attachment_index: {
          RecordIndex a;
          a.offset = rr.u64();
          a.length = rr.u64();
          for (int k = 0; k < 3; ++k) rr.u64();  // log time, create time, data size
          a.name = rr.string();
          s.attachments.push_back(a);
          break;
        }
        case Opcode::metadata_index: {
          RecordIndex m;
          m.offset = rr.u64();
          m.length = rr.u64();
          m.name = rr.string();
          s.metadata.push_back(m);
          break;
        }
        case Opcode::chunk_index: {
          ChunkIndex c;
          c.start_time = rr.u64();
          c.end_time = rr.u64();
          c.offset = rr.u64();
          c.length = rr.u64();
          rr.raw(rr.u32());  // message index offsets
          rr.u64();  // message index length
          c.compression = rr.string();
          c.compressed_size = rr.u64();
          c.uncompressed_size = rr.u64();
          if (c.offset < data_start_ || c.offset > size_ || c.length > size_ - c.offset) throw FormatError("a chunk index points outside the file");
          s.chunks.push_back(c);
          break;
        }
        default: break;
      }
    }
  } catch (const FormatError& e) {
    fail(summary_start, std::string("summary: ") + e.what());
  }
  return s;
}

std::vector<std::uint8_t> McapReader::record_at(std::uint64_t offset, Opcode opcode) {
  const auto head = read_at(offset, 9);
  ByteReader h(head);
  if (h.u8() != static_cast<std::uint8_t>(opcode)) fail(offset, "the index points at another kind of record");
  const std::uint64_t n = h.u64();
  if (n > size_ - offset - 9) fail(offset, "a record of " + std::to_string(n) + " bytes runs past the end of the file");
  return read_at(offset + 9, n);
}

std::vector<Message> McapReader::read_chunk(const ChunkIndex& chunk) {
  const auto content = record_at(chunk.offset, Opcode::chunk);
  try {
    ByteReader r(content);
    // A chunk's messages may be on channels that appeared in earlier chunks: the summary has them.
    if (!summary_cache_) summary_cache_ = summary().value_or(Summary{});
    Registry known;
    for (const auto& sch : summary_cache_->schemas) known.schemas[sch.id] = sch;
    for (const auto& c : summary_cache_->channels) known.channels[c.id] = c;
    return chunk_messages(r, known);
  } catch (const FormatError& e) {
    fail(chunk.offset, std::string("chunk: ") + e.what());
  }
}

Metadata McapReader::read_metadata(const RecordIndex& index) {
  const auto content = record_at(index.offset, Opcode::metadata);
  try {
    ByteReader r(content);
    return parse_metadata(r);
  } catch (const FormatError& e) {
    fail(index.offset, std::string("metadata: ") + e.what());
  }
}

Attachment McapReader::read_attachment(const RecordIndex& index) {
  const auto content = record_at(index.offset, Opcode::attachment);
  try {
    ByteReader r(content);
    return parse_attachment(r, content);
  } catch (const FormatError& e) {
    fail(index.offset, std::string("attachment: ") + e.what());
  }
}

}  // namespace viscera::mcap
