#include "viscera/protocol/binary_schemas.hpp"

namespace viscera::protocol {

namespace detail {
// Generated (cmake/embed_binary_schemas.cmake), in the order of VISCERA_BFBS_SCHEMAS in
// protocol/CMakeLists.txt.
extern const std::span<const std::uint8_t> kBinarySchemas[];
}  // namespace detail

namespace {
enum File { instrument_command, force_feedback, session, telemetry, surface_mesh, mesh_frame, event, scene_files, lockstep, lockstep_result };
BinarySchema schema(const char* table, File f) { return {std::string("viscera.wire.") + table, detail::kBinarySchemas[f]}; }
}  // namespace

BinarySchema binary_schema(Stream s) {
  switch (s) {
    case Stream::instrument_command: return schema("InstrumentCommand", instrument_command);
    case Stream::force_feedback: return schema("ForceFeedback", force_feedback);
    case Stream::session_request: return schema("SessionRequest", session);
    case Stream::scene_state: return schema("SceneState", session);
    case Stream::telemetry: return schema("Telemetry", telemetry);
    case Stream::surface_topology: return schema("SurfaceTopology", surface_mesh);
    case Stream::mesh_frame: return schema("MeshFrame", mesh_frame);
    case Stream::event: return schema("Event", event);
    case Stream::scene_files: return schema("SceneFiles", scene_files);
    case Stream::lockstep_step: return schema("LockstepStep", lockstep);
    case Stream::lockstep_result: return schema("LockstepResult", lockstep_result);
  }
  return schema("Event", event);
}

}  // namespace viscera::protocol
