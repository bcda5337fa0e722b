#pragma once
// Reads MCAP files, strictly: every record is checked against the bytes there are, a chunk's
// records against its CRC and size, a message against its channel. read_data() walks the data
// section in file order (schemas, channels, messages of each chunk, attachments, metadata) and
// stops at Data End, or at the first record that does not parse, saying where and why; summary()
// reads the footer and the summary section (statistics, channels, indexes) with its CRC.
// Every error is one line naming the file and the byte.
#include <cstdint>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "viscera/mcap/mcap_format.hpp"

namespace viscera::mcap {

/// Where a chunk is and what it holds (the summary's Chunk Index records).
struct ChunkIndex {
  std::uint64_t start_time = 0, end_time = 0;  ///< [ns] log times of its first and last message
  std::uint64_t offset = 0, length = 0;  ///< of the Chunk record in the file
  std::string compression;
  std::uint64_t compressed_size = 0, uncompressed_size = 0;
};

/// Where an attachment or a metadata record is (the summary's indexes).
struct RecordIndex {
  std::uint64_t offset = 0, length = 0;
  std::string name;
};

struct Summary {
  std::vector<Schema> schemas;
  std::vector<Channel> channels;
  std::optional<Statistics> statistics;
  std::vector<ChunkIndex> chunks;  ///< in file order
  std::vector<RecordIndex> attachments, metadata;
};

/// What read_data() met, in file order.
struct DataVisitor {
  std::function<void(const Schema&)> schema;
  std::function<void(const Channel&)> channel;
  std::function<void(const Message&)> message;
  std::function<void(const Attachment&)> attachment;
  std::function<void(const Metadata&)> metadata;
};

/// How the data section ended: at Data End (complete), or at a record that does not parse (a file
/// cut short by a crash, or damaged), and what was read before it.
struct DataEnd {
  bool complete = false;
  std::uint64_t offset = 0;  ///< of Data End, or of the record that failed
  std::string error;  ///< why it failed ("" when complete)
  std::uint64_t chunks = 0, messages = 0;
};

class McapReader {
 public:
  /// Opens a regular file and checks the leading magic and the Header; throws common::InputError
  /// naming the file otherwise.
  explicit McapReader(const std::string& path);
  const std::string& path() const { return path_; }
  std::uint64_t size() const { return size_; }
  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }

  /// Walks the data section. Messages come after their channel; each chunk's messages only once the
  /// whole chunk has been read, decompressed and checked (so a chunk cut short gives none).
  DataEnd read_data(const DataVisitor& visit);
  /// The summary, when the file ends with a footer whose summary CRC holds; nullopt for a file cut
  /// short (recover() rebuilds one); throws common::InputError for a footer that points outside
  /// the file or a summary CRC that does not match.
  std::optional<Summary> summary();
  /// The messages of one chunk of the summary, in the chunk's order (checked as read_data checks).
  std::vector<Message> read_chunk(const ChunkIndex& chunk);
  Metadata read_metadata(const RecordIndex& index);
  Attachment read_attachment(const RecordIndex& index);

 private:
  std::vector<std::uint8_t> read_at(std::uint64_t offset, std::uint64_t n);
  /// The content of the record at `offset` with that opcode (throws FormatError otherwise).
  std::vector<std::uint8_t> record_at(std::uint64_t offset, Opcode opcode);
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const;

  std::string path_, profile_, library_;
  std::ifstream in_;
  std::optional<Summary> summary_cache_;  // read_chunk's channels
  std::uint64_t size_ = 0, data_start_ = 0;
};

/// The messages, schemas, channels, attachments and metadata of a file up to its last complete
/// chunk, written to `out` as a complete, indexed file. Returns what was read (DataEnd says where
/// the input ended and why). `in` and `out` must differ.
DataEnd recover(const std::string& in, const std::string& out, const std::string& compression = "zstd");

}  // namespace viscera::mcap
