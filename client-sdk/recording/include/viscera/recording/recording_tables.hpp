#pragma once  // SPDX-License-Identifier: Apache-2.0
// A recording's streams as tables of columns (one row per message, in log-time order), for
// analysis in other tools (the Python package's DataFrames): each column named with its unit
// ("force_x_n", "tip_x_m"), each row decoded by the protocol's own verified decoders. Surface
// frames as one array of positions per organ mesh. No networking.
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "viscera/recording/recording.hpp"

namespace viscera::recording {

/// One column: its name (with its unit) and its values, one per row. Flags are bytes 0 or 1.
struct Column {
  std::string name;
  std::variant<std::vector<double>, std::vector<std::int64_t>, std::vector<std::uint64_t>, std::vector<std::uint8_t>, std::vector<std::string>>
      values;
};

/// One stream's messages: the log time [ns] of each row, the channel's source id and writer, and
/// the decoded fields. Messages that do not decode are counted, not tabulated.
struct StreamTable {
  std::vector<std::int64_t> log_time_ns;
  std::vector<Column> columns;
  std::uint64_t undecodable = 0;
  std::string last_error;  ///< why the newest undecodable message did not decode
};

/// The surface frames of one organ mesh (a scene's SurfaceTopology mesh_id): positions [m] of
/// `vertex_count` vertices per frame, frame after frame (float32, x y z per vertex).
struct FrameSeries {
  std::uint32_t mesh_id = 0;
  std::uint32_t vertex_count = 0;
  std::vector<std::uint32_t> triangles;  ///< 3 vertex indices per triangle (empty if the topology was not recorded)
  std::vector<float> rest_positions;  ///< [m] 3 per vertex (empty if the topology was not recorded)
  std::vector<std::int64_t> log_time_ns;
  std::vector<std::uint64_t> frame, tick;
  std::vector<double> sim_time_s;
  std::vector<float> positions;  ///< [m] frame-major: frame k's vertex i at 3 * (k * vertex_count + i)
  std::uint64_t mismatched = 0;  ///< frames dropped: another vertex count than the series' first
  /// The topology generation the series holds: the first seen of this mesh (0 as loaded); a cut
  /// makes later ones (docs/CUTTING.md).
  std::uint32_t topology_generation = 0;
  std::uint64_t later_generation_frames = 0;  ///< frames left out: of a later topology generation (after a cut)
  std::uint32_t last_topology_generation = 0;  ///< the newest generation seen
  bool generation_known = false;
};

struct RecordingTables {
  std::map<std::string, StreamTable> streams;  ///< by stream name (protocol::stream_name); mesh_frame holds the frames' metadata
  std::map<std::uint32_t, FrameSeries> frames;  ///< by mesh_id
};

/// The streams this reads into tables (every stream but the lockstep ones).
const std::vector<protocol::Stream>& tabulated_streams();

/// Reads the streams named (empty: tabulated_streams()) in one pass; `with_frames` also collects
/// the surface frames' positions. Throws common::InputError naming the file on a damaged chunk,
/// or the stream on a name that is not a tabulated stream.
RecordingTables read_tables(Recording& recording, const std::set<std::string>& streams = {}, bool with_frames = true);

}  // namespace viscera::recording
