#pragma once  // SPDX-License-Identifier: Apache-2.0
// A session recording opened for reading (the replayer, the trainer, viscera-record info): checked
// to be a complete viscera recording of a schema this build reads, its channels mapped back to
// their streams and keys, its scenes' files at hand. Errors are one line naming the file.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "viscera/mcap/integrity.hpp"
#include "viscera/mcap/mcap_reader.hpp"
#include "viscera/protocol/dds.hpp"

namespace viscera::recording {

struct RecordedChannel {
  std::uint16_t id = 0;
  protocol::Stream stream{};
  std::uint32_t source_id = 0;
  std::uint64_t writer = 0;
};

/// A file of a recorded scene.
struct RecordedFile {
  std::string role, path, attachment, sha256;
};

/// One scene's files as the server published them (metadata "viscera.scene").
struct RecordedScene {
  std::uint32_t generation = 0;
  std::uint64_t first_tick = 0;
  double sim_time_s = 0;
  std::string server_version, settings_json;
  std::uint64_t log_time_ns = 0;
  std::vector<RecordedFile> files;
  const RecordedFile* file(const std::string& role) const;
};

class Recording {
 public:
  /// Throws common::InputError naming the file: not MCAP, damaged, cut short (no summary: recover
  /// it first), not a viscera recording, or made with a newer protocol schema than this build's.
  explicit Recording(const std::string& path);
  const std::string& path() const { return reader_.path(); }
  const mcap::Summary& summary() const { return summary_; }
  /// Metadata "viscera.recording" (schema_version, domain_id, partition, streams, recorder).
  const std::map<std::string, std::string>& info() const { return info_; }
  /// The DDS domain it was recorded on (info's domain_id; 0 if absent); throws InputError naming
  /// the file if it is not a domain id (a whole number in [0, 230]).
  std::uint32_t domain_id() const;
  /// Metadata "viscera.drops" (absent from a recording that was recovered after a crash).
  const std::optional<std::map<std::string, std::string>>& drops() const { return drops_; }
  const std::map<std::uint16_t, RecordedChannel>& channels() const { return channels_; }
  const std::vector<RecordedScene>& scenes() const { return scenes_; }
  /// The attachment of that name's content; throws InputError if the recording has none.
  std::vector<std::uint8_t> attachment(const std::string& name);
  /// The whole file checked, record by record (mcap::check_integrity).
  mcap::Integrity integrity();
  /// [ns] log times of the first and last message (0, 0 when there is none).
  std::uint64_t start_ns() const;
  std::uint64_t end_ns() const;

  /// Each message with log time in [from_ns, to_ns], chunk by chunk in log-time order; `f` returns
  /// false to stop. Messages on channels of streams this build does not know are skipped.
  /// `read_ahead`: the next chunk is read and decompressed on a second thread while `f` runs (then
  /// `f` must not call this recording).
  void for_each(const std::function<bool(const RecordedChannel&, const mcap::Message&)>& f, std::uint64_t from_ns = 0,
                std::uint64_t to_ns = ~std::uint64_t{0}, bool read_ahead = false);

 private:
  mcap::McapReader reader_;
  mcap::Summary summary_;
  std::map<std::string, std::string> info_;
  std::optional<std::map<std::string, std::string>> drops_;
  std::map<std::uint16_t, RecordedChannel> channels_;
  std::vector<RecordedScene> scenes_;
};

}  // namespace viscera::recording
