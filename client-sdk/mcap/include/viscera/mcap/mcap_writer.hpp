#pragma once  // SPDX-License-Identifier: Apache-2.0
// Writes an MCAP file as the specification defines a complete, indexed one: messages in chunks
// (closed at a size or a span of log time, compressed), a message index after each chunk, the
// schemas and channels inside the chunk where they are first used (so that every chunk can be read
// on its own), attachments and metadata in the data section, then Data End with the data
// section's CRC, the summary (schemas, channels, statistics, metadata, attachment and chunk
// indexes), the summary offsets and the Footer with the summary's CRC. Each chunk is flushed to the
// file when it closes: a writer killed mid-session leaves a file readable up to its last chunk
// (McapReader, recover()).
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viscera/mcap/byte_codec.hpp"
#include "viscera/mcap/mcap_format.hpp"

namespace viscera::mcap {

struct WriterOptions {
  std::string profile;  ///< the Header's profile ("" : none in particular)
  std::string library = "viscera";
  std::string compression = "zstd";  ///< zstd | lz4 | "" (none)
  std::size_t chunk_bytes = std::size_t{4} << 20;  ///< close a chunk at this many uncompressed bytes
  std::uint64_t chunk_ns = 1'000'000'000;  ///< or when its messages span this much log time
  /// An existing file at the path: replaced (true) or refused (false: a recording is never lost to
  /// the next one). A symbolic link at the path is refused either way, never written through.
  bool replace = true;
};

class McapWriter {
 public:
  /// Creates `path` (an existing file: replaced or refused, WriterOptions::replace; a symbolic
  /// link: refused); throws std::runtime_error naming it and why when it cannot.
  McapWriter(const std::string& path, WriterOptions options = {});
  /// Closes the file if close() was not called (the summary is written).
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  std::uint16_t add_schema(const std::string& name, const std::string& encoding, std::vector<std::uint8_t> data);
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                            std::map<std::string, std::string> metadata = {});
  void add_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time, std::uint64_t publish_time,
                   std::span<const std::uint8_t> data);
  void add_attachment(const Attachment& a);
  void add_metadata(const Metadata& m);
  /// Closes the open chunk if its first message is `chunk_ns` older than `now_log_time` (a writer
  /// with no new messages still gets its last ones to the file within that span).
  void flush_if_due(std::uint64_t now_log_time);
  /// Ends the data section and writes the summary and the footer. Idempotent.
  void close();

  const Statistics& statistics() const { return stats_; }
  std::uint64_t bytes_written() const { return position_; }

 private:
  struct ChunkIndexEntry {
    std::uint64_t start_time, end_time, offset, length;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length, compressed_size, uncompressed_size;
  };
  void write(const std::vector<std::uint8_t>& bytes, bool data_section = true);
  void close_chunk();
  void schema_record(ByteWriter& w, const Schema& s) const;
  void channel_record(ByteWriter& w, const Channel& c) const;

  std::string path_;
  WriterOptions options_;
  struct CloseFile {
    // NOLINTNEXTLINE(cppcoreguidelines-owning-memory): the deleter of the unique_ptr that owns the file
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, CloseFile> file_;
  std::uint64_t position_ = 0;
  std::uint32_t data_crc_ = kCrc32Init;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::vector<bool> schema_in_file_, channel_in_file_;  // by id: written in a chunk already
  // The open chunk: its records (uncompressed) and, per channel, (log time, offset in the records).
  ByteWriter chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::optional<std::uint64_t> chunk_start_, chunk_end_;
  std::vector<ChunkIndexEntry> chunk_indexes_;
  std::vector<std::vector<std::uint8_t>> attachment_indexes_, metadata_indexes_;  // encoded records
  Statistics stats_;
  bool closed_ = false;
};

}  // namespace viscera::mcap
