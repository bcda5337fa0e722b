#pragma once  // SPDX-License-Identifier: Apache-2.0
// A session into an MCAP file, sample by sample as a StreamTap delivers them (no network here:
// the recorder feeds it, tests feed it their own samples). Channels, schemas, attachments and
// metadata as recording_format.hpp lays them out; each writer's gaps counted.
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "viscera/client/stream_tap.hpp"
#include "viscera/mcap/mcap_writer.hpp"
#include "viscera/recording/sequence_gaps.hpp"

namespace viscera::recording {

struct RecordingInfo {
  std::uint32_t domain_id = 0;
  std::string partition;
  std::vector<protocol::Stream> streams;
  std::string recorder;  ///< program and build
};

/// What has been recorded so far.
struct RecordingCounts {
  std::uint64_t messages = 0, bytes = 0;  ///< payload bytes
  std::map<protocol::Stream, std::uint64_t> per_stream;
  std::uint64_t scene_files = 0, attachments = 0;
  std::uint64_t undecodable_scene_files = 0;  ///< scene files whose payload did not verify (left out)
};

class RecordingWriter {
 public:
  /// Creates `path` and writes the recording's metadata at once (a recording cut short keeps it).
  RecordingWriter(const std::string& path, const RecordingInfo& info, mcap::WriterOptions options = {});
  /// One sample received at `log_time_ns` (made never to decrease). Scene files become attachments
  /// and metadata; every other stream's payload becomes a message.
  void add(const client::TapSample& s, std::uint64_t log_time_ns);
  /// Lets a quiet recording still close its chunk within its time span.
  void flush_if_due(std::uint64_t now_ns) { writer_.flush_if_due(now_ns); }
  /// Writes the drops (metadata "viscera.drops"), the summary and the footer.
  void close();

  const RecordingCounts& counts() const { return counts_; }
  const SequenceGaps& gaps() const { return gaps_; }
  /// The stream each writer (by its number) writes.
  const std::map<std::uint64_t, protocol::Stream>& writer_streams() const { return writer_streams_; }
  std::uint64_t file_bytes() const { return writer_.bytes_written(); }

 private:
  std::uint16_t channel(const client::TapSample& s, std::uint64_t writer_number);
  void scene_files(const client::TapSample& s, std::uint64_t log_time);

  mcap::McapWriter writer_;
  RecordingInfo info_;
  std::map<protocol::Stream, std::uint16_t> schemas_;
  std::map<std::tuple<protocol::Stream, std::uint64_t, std::uint32_t>, std::uint16_t> channels_;
  std::map<std::uint64_t, std::uint64_t> writer_numbers_;  // DDS handle -> 1, 2, ...
  std::map<std::uint64_t, protocol::Stream> writer_streams_;
  std::map<std::string, std::string> attached_;  // SHA-256 of each file attached -> its attachment's name
  std::set<std::string> names_;  // attachment names used
  SequenceGaps gaps_;
  RecordingCounts counts_;
  std::uint64_t last_log_time_ = 0;
  bool closed_ = false;
};

}  // namespace viscera::recording
