#pragma once  // SPDX-License-Identifier: Apache-2.0
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

namespace detail {
struct Registry;  ///< the schemas and channels met so far while reading
}  // namespace detail

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

/// A stretch of the data section that salvage_data() skipped: what was lost there and why.
struct Damage {
  std::uint64_t offset = 0, length = 0;  ///< [bytes] where the stretch starts in the file, and its size
  std::string what;
};

/// How the data section ended: at Data End (complete), or at a record that does not parse (a file
/// cut short by a crash, or damaged), and what was read before it.
struct DataEnd {
  bool complete = false;
  std::uint64_t offset = 0;  ///< of Data End, or of the record that failed
  std::string error;  ///< why it failed ("" when complete)
  std::uint64_t chunks = 0, messages = 0, attachments = 0;
  std::vector<Damage> damaged;  ///< salvage_data(): every stretch skipped, in file order (read_data stops at the first)
  /// Nothing of the data section was lost: complete, or cut exactly after a record (a killed
  /// writer's file, whose summary alone is missing), with no stretch skipped.
  bool intact() const { return damaged.empty(); }
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
  /// Walks the data section as read_data() does, but keeps going past damage: a record that does
  /// not parse (a CRC that does not match, a chunk that does not decompress) is skipped whole when
  /// its length still holds, and otherwise the walk resumes at the next chunk or attachment whose
  /// CRC holds; a tail of zero bytes (space a crash left unwritten) ends it. Every stretch skipped
  /// is in DataEnd::damaged. Channels and schemas come from the summary too, where it reads, so the
  /// messages after a damaged chunk keep their channels.
  DataEnd salvage_data(const DataVisitor& visit);
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
  /// Reads the record at `at`, visits what it holds and returns its size with opcode and length;
  /// throws FormatError or common::InputError for a record that does not parse.
  std::uint64_t read_record(std::uint64_t at, detail::Registry& known, const DataVisitor& visit, DataEnd& end);
  /// Whether a chunk or attachment whose CRC holds starts at `at` (where a walk past damage resumes).
  bool checked_record_at(std::uint64_t at);
  /// The first offset after `from` where checked_record_at() holds, or the file's size.
  std::uint64_t next_checked_record(std::uint64_t from);
  /// Whether every byte from `from` to the end of the file is zero.
  bool zeros_to_end(std::uint64_t from);
  /// The content of the record at `offset` with that opcode (throws FormatError otherwise).
  std::vector<std::uint8_t> record_at(std::uint64_t offset, Opcode opcode);
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const;

  std::string path_, profile_, library_;
  std::ifstream in_;
  // The bytes read last, from window_start_: small reads (a record's 9-byte head, a short record)
  // come from it, so a walk over many small records reads the file in blocks, not a seek and a
  // read per record (recover of 50 MB of 9-byte records took more than 60 s).
  std::vector<std::uint8_t> window_;
  std::uint64_t window_start_ = 0;
  std::optional<Summary> summary_cache_;  // read_chunk's channels
  std::uint64_t size_ = 0, data_start_ = 0;
};

/// The messages, schemas, channels, attachments and metadata of every record of a file that is
/// intact (salvage_data()), written to `out` as a complete, indexed file. Returns what was read:
/// where the input ended and why, and every stretch lost. `out` must not be `in` (by device and
/// inode: a hard or symbolic link to `in` is refused too).
DataEnd recover(const std::string& in, const std::string& out, const std::string& compression = "zstd");

}  // namespace viscera::mcap
