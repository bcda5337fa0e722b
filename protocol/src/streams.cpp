#include "viscera/protocol/streams.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/protocol/typed_reader.hpp"

namespace viscera::protocol {

namespace {
template <Stream S>
bool verifies(std::span<const std::uint8_t> payload, std::string* why) {
  return Message<S>::decode(payload, why).has_value();
}

using enum Reliability;
using enum Durability;
// clang-format off
constexpr std::array<StreamInfo, kStreamCount> kStreams{{
  // stream                       topic                          schema               file                  reliability  depth durability       state  droppable session
  {Stream::instrument_command, "viscera_instrument_command", "InstrumentCommand",  "instrument_command", best_effort, 1,  volatile_only,   false, true,  true,  verifies<Stream::instrument_command>},
  {Stream::force_feedback,     "viscera_force_feedback",     "ForceFeedback",      "force_feedback",     best_effort, 1,  volatile_only,   false, true,  true,  verifies<Stream::force_feedback>},
  {Stream::session_request,    "viscera_session_request",    "SessionRequest",     "session",            reliable,    16, volatile_only,   false, false, true,  verifies<Stream::session_request>},
  {Stream::scene_state,        "viscera_scene_state",        "SceneState",         "session",            reliable,    1,  transient_local, true,  false, true,  verifies<Stream::scene_state>},
  {Stream::telemetry,          "viscera_telemetry",          "Telemetry",          "telemetry",          best_effort, 1,  volatile_only,   false, true,  true,  verifies<Stream::telemetry>},
  {Stream::surface_topology,   "viscera_surface_topology",   "SurfaceTopology",    "surface_mesh",       reliable,    16, transient_local, true,  false, true,  verifies<Stream::surface_topology>},
  {Stream::mesh_frame,         "viscera_mesh_frame",         "MeshFrame",          "mesh_frame",         reliable,    1,  volatile_only,   false, true,  true,  verifies<Stream::mesh_frame>},
  {Stream::event,              "viscera_event",              "Event",              "event",              reliable,    64, volatile_only,   false, false, true,  verifies<Stream::event>},
  {Stream::scene_files,        "viscera_scene_files",        "SceneFiles",         "scene_files",        reliable,    1,  transient_local, true,  false, true,  verifies<Stream::scene_files>},
  {Stream::lockstep_step,      "viscera_lockstep_step",      "LockstepStep",       "lockstep",           reliable,    0,  volatile_only,   false, false, false, verifies<Stream::lockstep_step>},
  {Stream::lockstep_result,    "viscera_lockstep_result",    "LockstepResult",     "lockstep_result",    reliable,    0,  volatile_only,   false, false, false, verifies<Stream::lockstep_result>},
}};
// clang-format on
constexpr bool in_order() {
  for (int k = 0; k < kStreamCount; ++k)
    if (static_cast<int>(kStreams[static_cast<std::size_t>(k)].stream) != k) return false;
  return true;
}
static_assert(in_order(), "kStreams lists the streams in the order of enum Stream");
}  // namespace

const std::array<StreamInfo, kStreamCount>& streams() { return kStreams; }
const StreamInfo& stream_info(Stream s) { return kStreams.at(static_cast<std::size_t>(s)); }

}  // namespace viscera::protocol
