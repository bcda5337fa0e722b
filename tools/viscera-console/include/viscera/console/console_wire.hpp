#pragma once  // SPDX-License-Identifier: Apache-2.0
// What the bridge sends a browser (docs/CONSOLE.md): the surface topology and the mesh frames as
// binary WebSocket messages (little-endian, float32 positions the page views without copying),
// everything else as small JSON objects with a "type".
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "viscera/console/force_decimator.hpp"
#include "viscera/protocol/messages.hpp"

namespace viscera::console {

/// Binary message kinds (the first byte).
enum class BinaryKind : std::uint8_t { topology = 1, frame = 2 };
/// Bytes before the arrays of a binary message (a multiple of 8, so the page's typed views align).
/// Topology: kind at 0, mesh_id at 4, vertex count at 8, triangle count at 12, topology
/// generation at 16; frame: kind at 0, mesh_id at 4, vertex count at 8, topology generation at 12,
/// frame number at 16, simulated time at 24, server wall time [ms] at 32 (doubles).
inline constexpr std::size_t kTopologyHeaderBytes = 24;
inline constexpr std::size_t kFrameHeaderBytes = 40;

/// [u8 kind=1, 3 pad][u32 mesh_id][u32 vertex_count][u32 triangle_count]
/// [f32 rest positions, 3 per vertex][u32 vertex indices, 3 per triangle]
std::string encode_topology(const protocol::SurfaceTopology& t);
/// [u8 kind=2, 3 pad][u32 mesh_id][u32 vertex_count][4 pad][f64 frame][f64 sim_time_s]
/// [f64 server stamp as wall-clock ms since the epoch][f32 positions, 3 per vertex]
/// `server_wall_ms`: when the server took the frame, on the wall clock (for the page's delay).
std::string encode_frame(const protocol::MeshFrame& m, double server_wall_ms);

nlohmann::json to_json(const protocol::Scene& s);
nlohmann::json to_json(const protocol::TelemetryReport& t);
nlohmann::json to_json(const protocol::Event& e);
/// {"type": "forces", "station": ..., "instruments": [{"id", "t_s", "peak_n", "force", "contact", "contact_point", "tip", "max_edge_strain",
/// "tip_strain"}]}
nlohmann::json forces_json(const std::vector<ForceSummary>& f, const std::vector<std::pair<std::uint32_t, protocol::Vector3>>& tips);

}  // namespace viscera::console
