#pragma once  // SPDX-License-Identifier: Apache-2.0
// A reader of one stream that hands over decoded messages: every payload goes through the
// stream's decoder (messages.hpp), and those that fail are counted with the newest reason, so a
// receiver never decodes by hand and a rejected payload is never silent.
#include <cstdint>
#include <string>
#include <utility>

#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/messages.hpp"

namespace viscera::protocol {

/// The message type and decoder of each stream.
template <Stream S>
struct Message;
#define VISCERA_STREAM_MESSAGE(S, T, DECODE)                                                                     \
  template <>                                                                                                    \
  struct Message<Stream::S> {                                                                                    \
    using type = T;                                                                                              \
    static std::optional<T> decode(std::span<const std::uint8_t> b, std::string* why) { return DECODE(b, why); } \
  };
VISCERA_STREAM_MESSAGE(instrument_command, Command, decode_command)
VISCERA_STREAM_MESSAGE(force_feedback, Force, decode_force)
VISCERA_STREAM_MESSAGE(session_request, SessionRequest, decode_session_request)
VISCERA_STREAM_MESSAGE(scene_state, Scene, decode_scene)
VISCERA_STREAM_MESSAGE(telemetry, TelemetryReport, decode_telemetry)
VISCERA_STREAM_MESSAGE(surface_topology, SurfaceTopology, decode_surface_topology)
VISCERA_STREAM_MESSAGE(mesh_frame, MeshFrame, decode_mesh_frame)
VISCERA_STREAM_MESSAGE(event, Event, decode_event)
VISCERA_STREAM_MESSAGE(scene_files, SceneFiles, decode_scene_files)
VISCERA_STREAM_MESSAGE(lockstep_step, LockstepStep, decode_lockstep_step)
VISCERA_STREAM_MESSAGE(lockstep_result, LockstepResult, decode_lockstep_result)
#undef VISCERA_STREAM_MESSAGE

/// Payloads a receiver refused: how many, and why the newest was.
struct Rejections {
  std::uint64_t count = 0;
  std::string last_reason;
  void add(std::string why) {
    ++count;
    last_reason = std::move(why);
  }
};

template <Stream S>
class TypedReader {
 public:
  using Type = typename Message<S>::type;
  explicit TypedReader(Participant& p, ReaderOptions options = {}) : reader_(p, S, options) {}
  /// Calls f(message, received) for each sample that decodes; counts the others in `rejections`.
  /// Returns how many samples were taken.
  template <class F>
  int take(F&& f, Rejections& rejections) {
    return reader_.take([&](const Received& r) {
      std::string why;
      if (auto m = Message<S>::decode(r.payload, &why))
        f(std::move(*m), r);
      else
        rejections.add(std::string(stream_name(S)) + ": " + why);
    });
  }
  bool wait(std::chrono::nanoseconds timeout) { return reader_.wait(timeout); }
  int alive_writers() const { return reader_.alive_writers(); }
  Reader& raw() { return reader_; }

 private:
  Reader reader_;
};

}  // namespace viscera::protocol
