// A client compiled against schema 1 (tests/protocol/schema_v1), before ForceFeedback gained a  // SPDX-License-Identifier: Apache-2.0
// field: it must still claim an instrument of today's server, press the liver and feel it. It
// uses only the schema-1 generated code and the DDS wrapper, as a client in the field would.
// Usage: old_client DOMAIN CLIENT_ID INSTRUMENT SECONDS. Exit 0 when it received forces that
// push the probe out of the tissue; prints what it saw.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "viscera/protocol/dds.hpp"

#include "force_feedback_generated.h"
#include "instrument_command_generated.h"
#include "session_generated.h"

namespace v1 = viscera::wire_v1;
namespace proto = viscera::protocol;

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: old_client DOMAIN CLIENT_ID INSTRUMENT SECONDS\n");
    return 2;
  }
  const auto domain = static_cast<std::uint32_t>(std::atoi(argv[1]));
  const auto client = static_cast<std::uint32_t>(std::atoi(argv[2])), instrument = static_cast<std::uint32_t>(std::atoi(argv[3]));
  const double seconds = std::atof(argv[4]);
  proto::Participant participant(domain);
  proto::Writer commands(participant, proto::Stream::instrument_command), sessions(participant, proto::Stream::session_request);
  proto::Reader forces(participant, proto::Stream::force_feedback), scene(participant, proto::Stream::scene_state);

  // Claim, and learn the organ's bounds from the scene state.
  double top = 0, cx = 0, cy = 0;
  bool claimed = false;
  for (int attempt = 0; attempt < 50 && !claimed; ++attempt) {
    flatbuffers::FlatBufferBuilder b;
    b.Finish(v1::CreateSessionRequest(b, client, v1::SessionAction::claim_instrument, instrument));
    sessions.write(client, {b.GetBufferPointer(), b.GetSize()});
    scene.wait(std::chrono::milliseconds(100));
    scene.take([&](const proto::Received& r) {
      flatbuffers::Verifier v(r.payload.data(), r.payload.size());
      if (!v1::VerifySceneStateBuffer(v)) return;
      const auto* s = v1::GetSceneState(r.payload.data());
      if (!s->instruments() || !s->organ_bounds_max() || !s->organ_bounds_min()) return;
      top = s->organ_bounds_max()->z();
      cx = 0.5 * (s->organ_bounds_min()->x() + s->organ_bounds_max()->x());
      cy = 0.5 * (s->organ_bounds_min()->y() + s->organ_bounds_max()->y());
      for (const auto* i : *s->instruments()) claimed |= i->instrument_id() == instrument && i->owner_client_id() == client;
    });
  }
  if (!claimed) {
    std::fprintf(stderr, "old_client: could not claim instrument %u\n", instrument);
    return 1;
  }
  // Move down from 1 cm above the top by 4 cm over the run, at 1 kHz.
  int received = 0, pushing_out = 0, bad = 0;
  std::uint64_t seq = 0;
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  for (;;) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t >= seconds) break;
    flatbuffers::FlatBufferBuilder b;
    const v1::Vec3 tip(cx, cy, top + 0.01 - 0.04 * t / seconds);
    const v1::Quat q(1, 0, 0, 0);
    b.Finish(v1::CreateInstrumentCommand(b, instrument, client, ++seq, proto::now_ns(), &tip, &q, 0.5, 0));
    commands.write(instrument, {b.GetBufferPointer(), b.GetSize()});
    forces.take([&](const proto::Received& r) {
      flatbuffers::Verifier v(r.payload.data(), r.payload.size());
      if (!v1::VerifyForceFeedbackBuffer(v)) {
        ++bad;
        return;
      }
      const auto* f = v1::GetForceFeedback(r.payload.data());
      if (f->client_id() != client) return;
      ++received;
      if (f->local_model() && f->local_model()->in_contact() && f->force() && f->force()->z() > 0) ++pushing_out;
    });
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  flatbuffers::FlatBufferBuilder b;
  b.Finish(v1::CreateSessionRequest(b, client, v1::SessionAction::release_instrument, instrument));
  sessions.write(client, {b.GetBufferPointer(), b.GetSize()});
  std::printf("old_client: %d forces received (schema 1 verifier), %d in contact pushing the probe out, %d failed verification\n", received,
              pushing_out, bad);
  return received > 500 && pushing_out > 100 && bad == 0 ? 0 : 1;
}
