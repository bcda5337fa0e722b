// Schema evolution: a field added at the end of a table (ForceFeedback.penetration_m, schema 2)  // SPDX-License-Identifier: Apache-2.0
// must not break clients compiled against schema 1, and messages of schema-1 writers must still
// decode. Schema 1 is the frozen copy in tests/protocol/schema_v1 (namespace viscera::wire_v1).
#include <gtest/gtest.h>

#include "viscera/protocol/messages.hpp"  // schema 2 (current)

#include "force_feedback_generated.h"  // schema 1, from tests/protocol/schema_v1
#include "instrument_command_generated.h"
#include "session_generated.h"
#include "telemetry_generated.h"

namespace v1 = viscera::wire_v1;
using namespace viscera::protocol;

TEST(SchemaEvolution, OldReaderReadsNewForceFeedback) {
  Force f;
  f.instrument_id = 2;
  f.client_id = 9;
  f.command_seq = 1234;
  f.command_client_stamp_ns = 555;
  f.force = {0.1, -0.2, 1.5};
  f.in_contact = true;
  f.contact_normal = {0, 0, 1};
  f.stiffness[8] = 800;
  f.step_time_ns = 180000;
  f.penetration_m = 0.0021;  // fields schema 1 does not know: penetration (schema 2), tick (schema 7)
  f.tick = 987654321;
  f.max_edge_strain = 0.25;  // schema 8
  f.cutting = true;  // schema 17
  f.tip_strain = 0.2;  // schema 18
  const auto bytes = encode(f);
  flatbuffers::Verifier verifier(bytes.data(), bytes.size());
  ASSERT_TRUE(v1::VerifyForceFeedbackBuffer(verifier));
  const auto* old = v1::GetForceFeedback(bytes.data());
  EXPECT_EQ(old->instrument_id(), 2u);
  EXPECT_EQ(old->client_id(), 9u);
  EXPECT_EQ(old->command_seq(), 1234u);
  EXPECT_EQ(old->command_client_stamp_ns(), 555);
  EXPECT_EQ(old->force()->z(), 1.5);
  EXPECT_EQ(old->step_time_ns(), 180000);
  ASSERT_NE(old->local_model(), nullptr);
  EXPECT_TRUE(old->local_model()->in_contact());
  EXPECT_EQ(old->local_model()->stiffness()->m22(), 800);
}

TEST(SchemaEvolution, NewReaderReadsOldMessagesWithDefaults) {
  flatbuffers::FlatBufferBuilder b;
  const v1::Vec3 force(0, 0, 2.5), point(0.01, 0.02, 0.03), normal(0, 0, 1);
  const v1::Mat3 K(0, 0, 0, 0, 0, 0, 0, 0, 400);
  const auto model = v1::CreateLocalForceModel(b, &point, &normal, &K, true);
  b.Finish(v1::CreateForceFeedback(b, 3, 9, 77, 1000, 2000, &force, nullptr, model, 150000));
  std::string why;
  const auto f = decode_force({b.GetBufferPointer(), b.GetSize()}, &why);
  ASSERT_TRUE(f) << why;
  EXPECT_EQ(f->command_seq, 77u);
  EXPECT_EQ(f->force[2], 2.5);
  EXPECT_EQ(f->stiffness[8], 400);
  EXPECT_EQ(f->penetration_m, 0.0);  // absent: the schema's default
  EXPECT_EQ(f->friction_mu, 0.0);  // schema 20: an older server's model is rendered without a cone
  EXPECT_EQ(f->tick, 0u);  // an older server stamps no tick: a recording of it cannot be re-simulated
  EXPECT_EQ(f->max_edge_strain, 0.0);  // nor the organ's strain (schema 8)
  EXPECT_FALSE(f->cutting);  // nor a blade cutting (schema 17)
  EXPECT_EQ(f->tip_strain, 0.0);  // nor the strain at the instrument (schema 18)

  flatbuffers::FlatBufferBuilder c;
  const v1::Vec3 tip(0.0, 0.01, 0.05);
  const v1::Quat q(1, 0, 0, 0);
  c.Finish(v1::CreateInstrumentCommand(c, 1, 9, 5, 42, &tip, &q, 0.3, 0));
  const auto cmd = decode_command({c.GetBufferPointer(), c.GetSize()}, &why);
  ASSERT_TRUE(cmd) << why;
  EXPECT_EQ(cmd->seq, 5u);
  EXPECT_EQ(cmd->tip_position[2], 0.05);
}

TEST(SchemaEvolution, OldClientReadsTheSceneStateOfSchema6) {
  Scene sc;
  sc.name = "liver";
  sc.physics_rate_hz = 1000;
  sc.paused = true;
  sc.instruments.push_back({2, true, 0.004, 31});
  sc.generation = 2;  // the fields schema 1 does not know:
  sc.material = {"liver", 5000, 0.45, 1060, 4.8, 2};
  sc.available_scenes = {"liver", "liver-12k"};
  sc.recent_requests.push_back({900, 17, Action::load_scene, true, "loaded scene liver"});
  sc.unreadable_scenes = {"broken: broken.json:4: JSON: number overflow parsing '1e999'"};  // schema 6
  const auto bytes = encode(sc);
  std::string why;
  const auto now = decode_scene(bytes, &why);
  ASSERT_TRUE(now) << why;
  EXPECT_EQ(now->unreadable_scenes, sc.unreadable_scenes);
  flatbuffers::Verifier verifier(bytes.data(), bytes.size());
  ASSERT_TRUE(v1::VerifySceneStateBuffer(verifier));
  const auto* old = v1::GetSceneState(bytes.data());
  EXPECT_EQ(old->scene_name()->str(), "liver");
  EXPECT_EQ(old->physics_rate_hz(), 1000);
  EXPECT_TRUE(old->paused());
  ASSERT_EQ(old->instruments()->size(), 1u);
  EXPECT_EQ(old->instruments()->Get(0)->owner_client_id(), 31u);
  EXPECT_EQ(old->instruments()->Get(0)->kind(), v1::InstrumentKind::grasper);
}

TEST(SchemaEvolution, SchemaOneSessionRequestsStillDecode) {
  flatbuffers::FlatBufferBuilder b;
  b.Finish(v1::CreateSessionRequest(b, 9, v1::SessionAction::claim_instrument, 2));
  std::string why;
  const auto r = decode_session_request({b.GetBufferPointer(), b.GetSize()}, &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->action, Action::claim_instrument);
  EXPECT_EQ(r->instrument_id, 2u);
  EXPECT_EQ(r->request_seq, 0u);  // absent: defaults
  EXPECT_TRUE(r->material.empty());
}

TEST(SchemaEvolution, TelemetryOfSchema6AndOfEarlierServersReadBothWays) {
  // Schema 5 adds Telemetry.missed_slots, schema 6 the rejections by reason; a console of schema 1
  // reads the rest of today's report...
  const auto bytes = encode(TelemetryReport{7, 30'000, 12, 6, 1000.0, 600, 900, 1400, 25, 3, 3, 2, 1});
  flatbuffers::Verifier verifier(bytes.data(), bytes.size());
  ASSERT_TRUE(v1::VerifyTelemetryBuffer(verifier));
  const auto* old = v1::GetTelemetry(bytes.data());
  EXPECT_EQ(old->steps(), 30'000u);
  EXPECT_EQ(old->overruns(), 12u);
  EXPECT_EQ(old->rejected_messages(), 6u);
  EXPECT_EQ(old->physics_rate_hz(), 1000.0);
  std::string why;
  const auto now = decode_telemetry(bytes, &why);
  ASSERT_TRUE(now) << why;
  EXPECT_EQ(now->rejected_malformed, 3u);
  EXPECT_EQ(now->rejected_not_owner, 2u);
  EXPECT_EQ(now->rejected_unknown_instrument, 1u);
  // ...and today's decoder reads a report of an earlier server with no slots missed.
  flatbuffers::FlatBufferBuilder b;
  b.Finish(v1::CreateTelemetry(b, 7, 29'990, 998.0, 600, 900, 1400, 25, 12, 1));
  const auto t = decode_telemetry({b.GetBufferPointer(), b.GetSize()}, &why);
  ASSERT_TRUE(t) << why;
  EXPECT_EQ(t->late_ticks, 12u);
  EXPECT_EQ(t->missed_slots, 0u);  // absent: the schema's default
  EXPECT_EQ(t->rejected_malformed + t->rejected_not_owner + t->rejected_unknown_instrument, 0u);
  EXPECT_EQ(t->rejected_messages, 1u);
  EXPECT_EQ(t->physics_rate_hz, 998.0);
}
