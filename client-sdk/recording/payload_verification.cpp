#include "viscera/recording/payload_verification.hpp"

#include "viscera/protocol/messages.hpp"

namespace viscera::recording {

bool payload_decodes(protocol::Stream stream, std::span<const std::uint8_t> payload, std::string* why) {
  namespace proto = viscera::protocol;
  switch (stream) {
    case proto::Stream::instrument_command: return proto::decode_command(payload, why).has_value();
    case proto::Stream::force_feedback: return proto::decode_force(payload, why).has_value();
    case proto::Stream::session_request: return proto::decode_session_request(payload, why).has_value();
    case proto::Stream::scene_state: return proto::decode_scene(payload, why).has_value();
    case proto::Stream::telemetry: return proto::decode_telemetry(payload, why).has_value();
    case proto::Stream::surface_topology: return proto::decode_surface_topology(payload, why).has_value();
    case proto::Stream::mesh_frame: return proto::decode_mesh_frame(payload, why).has_value();
    case proto::Stream::event: return proto::decode_event(payload, why).has_value();
    case proto::Stream::scene_files: return proto::decode_scene_files(payload, why).has_value();
    case proto::Stream::lockstep_step: return proto::decode_lockstep_step(payload, why).has_value();
    case proto::Stream::lockstep_result: return proto::decode_lockstep_result(payload, why).has_value();
  }
  *why = "a stream this build does not know";
  return false;
}

}  // namespace viscera::recording
