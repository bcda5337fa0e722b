// The whole server in one process, its endpoints in memory instead of DDS: the physics thread, the  // SPDX-License-Identifier: Apache-2.0
// command thread answering every command from the newest snapshot, and session control building a
// new material in the background, all at once while a client presses. Run under ThreadSanitizer
// by deploy/test.sh (the snapshot hand-over, the instrument table, the run-time control), and
// under ASan + UBSan with the other unit tests.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <thread>

#include <gtest/gtest.h>

#include "viscera/protocol/messages.hpp"

#include "memory_endpoints.hpp"

namespace viscera::runtime {
namespace {

namespace proto = viscera::protocol;
using testing::LiveServer;
using testing::MemoryEndpoints;

TEST(ServerThreads, CommandsAnsweredWhileThePhysicsStepsAndAMaterialIsBuilt) {
  LiveServer live(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  MemoryEndpoints& endpoints = live.endpoints;

  proto::SessionRequest claim{7, proto::Action::claim_instrument, 1};
  endpoints.push_request(claim);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  // Press down from above the organ's top for 1.2 s at 1 kHz; change the material and the rate,
  // pause and resume meanwhile.
  const auto scenes = endpoints.decoded<proto::Scene>(endpoints.scenes, proto::decode_scene);
  ASSERT_FALSE(scenes.empty());
  const auto& b = scenes.back();
  const double cx = 0.5 * (b.bounds_min[0] + b.bounds_max[0]), cy = 0.5 * (b.bounds_min[1] + b.bounds_max[1]), z0 = b.bounds_max[2] + 0.005;
  int sent = 0;
  for (int k = 1; k <= 1200; ++k) {
    proto::Command c;
    c.instrument_id = 1;
    c.client_id = 7;
    c.seq = static_cast<std::uint64_t>(k);
    c.client_stamp_ns = proto::now_ns();
    c.tip_position = {cx, cy, z0 - 0.03 * k / 1200.0};
    endpoints.push_command(c);
    ++sent;
    if (k == 300) {
      proto::SessionRequest r{8, proto::Action::set_material, 0, 1};
      r.material.youngs_modulus_pa = 7000;
      endpoints.push_request(r);
    }
    if (k == 600) endpoints.push_request({8, proto::Action::pause, 0});
    if (k == 700) endpoints.push_request({8, proto::Action::resume, 0});
    if (k == 800) {
      proto::SessionRequest r{8, proto::Action::set_physics_rate, 0, 2};
      r.physics_rate_hz = 500;
      endpoints.push_request(r);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // The material is built in the background: wait for its outcome (seconds under ThreadSanitizer).
  for (int k = 0; k < 600; ++k) {
    const auto now = endpoints.decoded<proto::Scene>(endpoints.scenes, proto::decode_scene);
    if (now.back().material.youngs_modulus_pa == 7000 && now.back().physics_rate_hz == 500) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const ServerStats& stats = live.stop();

  const auto forces = endpoints.decoded<proto::Force>(endpoints.forces, proto::decode_force);
  std::size_t answers = 0, in_contact = 0;
  for (const auto& f : forces) {
    answers += f.step_time_ns == 0;  // the command thread's immediate answers
    in_contact += f.in_contact;
  }
  const auto events = endpoints.decoded<proto::Event>(endpoints.events, proto::decode_event);
  const auto has = [&](proto::EventKind k) { return std::any_of(events.begin(), events.end(), [&](const auto& e) { return e.kind == k; }); };
  const auto last = endpoints.decoded<proto::Scene>(endpoints.scenes, proto::decode_scene).back();
  std::cout << "[ figure ] in one process: " << stats.ticks << " ticks, " << sent << " commands, " << answers << " answered at once, "
            << forces.size() - answers << " forces after ticks, " << in_contact << " in contact, " << endpoints.frames.load() << " mesh frames\n";
  // Every command is the newest when the command thread takes it, or is overtaken by a newer one
  // in the same take: most are answered; none is answered twice.
  EXPECT_GT(answers, 0.8 * sent);
  EXPECT_LE(answers, static_cast<std::size_t>(sent));
  EXPECT_GT(in_contact, 100u);
  EXPECT_TRUE(has(proto::EventKind::instrument_claimed));
  EXPECT_TRUE(has(proto::EventKind::material_changed));
  EXPECT_TRUE(has(proto::EventKind::paused));
  EXPECT_TRUE(has(proto::EventKind::resumed));
  EXPECT_TRUE(has(proto::EventKind::physics_rate_changed));
  EXPECT_EQ(last.physics_rate_hz, 500);
  EXPECT_EQ(last.material.youngs_modulus_pa, 7000);
  EXPECT_GT(endpoints.topologies.load(), 0);
  EXPECT_GT(endpoints.frames.load(), 0);
  EXPECT_EQ(stats.rejected, 0u);
}

}  // namespace
}  // namespace viscera::runtime
