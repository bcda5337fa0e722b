// A tool that appears inside the tissue (claimed there, or held there while the organ is reset to  // SPDX-License-Identifier: Apache-2.0
// rest) must not strike it with the contact's whole force in one step. The reference is another
// path to the same pose: the same probe pressed in from above the organ at the scene's speed
// limit, 0.5 m/s, the speed at which a withdrawn tool enters (the held force depends on the entry
// speed: pressed in at 0.1 m/s the 1.5k liver holds 1.02 N, at 0.5 m/s 0.60 N). A device
// claimed 2 cm deep must feel what the pressed one feels once both have settled, never much more
// on the way, and must never make the organ go unstable. The whole server in one process, in
// lockstep, its endpoints in memory.
#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/simulation_server.hpp"

#include "memory_endpoints.hpp"

namespace viscera::runtime {
namespace {

namespace proto = viscera::protocol;
using testing::MemoryEndpoints;
using testing::MemoryLockstepLink;

constexpr int kTicks = 700;
constexpr int kResetAt = 350;  // an instructor resets the organ while the probe is held in it
// Below the top of the organ's bounds, at its centre: 2 cm, and 3.5 cm, where the tool's centre
// at rest lies deeper than the contact's depth limit (2 cm) and only the surface's inside test
// finds it (surface_exit.hpp).
constexpr double kDepthM = 0.02, kDeeperM = 0.035;

struct Run {
  std::vector<double> force_z;  // stepped force on the tool per tick [N]
  int resets = 0;  // physics_reset events (the organ went unstable)
  std::string first_reset;
};

/// `deep`: the probe's first command is already `depth_m` below the top; otherwise it starts 2 mm
/// above and goes down at 0.5 m/s. Either way it then holds, and the organ is reset at kResetAt.
Run run(const std::string& scene_file, bool deep, double depth_m) {
  SceneSpec spec = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_file);
  MemoryEndpoints endpoints;
  MemoryLockstepLink link;
  SimulationServer server(spec, endpoints, {}, TickBudget{1e9}, true);
  const auto scene = endpoints.decoded<proto::Scene>(endpoints.scenes, proto::decode_scene).back();
  const double cx = 0.5 * (scene.bounds_min[0] + scene.bounds_max[0]), cy = 0.5 * (scene.bounds_min[1] + scene.bounds_max[1]);
  const double top = scene.bounds_max[2], dt = 1.0 / scene.physics_rate_hz;
  std::vector<proto::LockstepStep> steps;
  for (int k = 0; k <= kTicks; ++k) {
    proto::LockstepStep s;
    s.tick = static_cast<std::uint64_t>(k) + 1;
    s.sim_time_s = k * dt;
    if (k == 0) s.requests.push_back(proto::encode(proto::SessionRequest{7, proto::Action::claim_instrument, 1}));
    if (k == kResetAt) s.requests.push_back(proto::encode(proto::SessionRequest{8, proto::Action::reset, 0, 1}));
    proto::Command c;
    c.instrument_id = 1;
    c.client_id = 7;
    c.seq = static_cast<std::uint64_t>(k) + 1;
    const double z = deep ? top - depth_m : std::max(top - depth_m, top + 0.002 - 0.5 * k * dt);
    c.tip_position = {cx, cy, z};
    s.commands.push_back(proto::encode(c));
    steps.push_back(s);
  }
  std::atomic<bool> stop{false};
  std::thread t([&] { server.run_lockstep(stop, link, {}); });
  for (const auto& s : steps) link.push_step(s);
  const auto results = link.wait_results(steps.size(), std::chrono::seconds(600));
  stop = true;
  t.join();
  Run r;
  std::string why;
  for (const auto& res : results) {
    for (const auto& p : res.forces)
      if (const auto f = proto::decode_force(p, &why); f && f->step_time_ns > 0) r.force_z.push_back(f->force[2]);
    for (const auto& p : res.events)
      if (const auto e = proto::decode_event(p, &why); e && e->kind == proto::EventKind::physics_reset && r.resets++ == 0) r.first_reset = e->text;
  }
  return r;
}

double mean(const std::vector<double>& v, int from, int to) {
  double s = 0;
  for (int k = from; k < to; ++k) s += v[static_cast<std::size_t>(k)];
  return s / (to - from);
}

void expect_entered_gently(const std::string& scene_file, double depth_m = kDepthM) {
  SCOPED_TRACE(scene_file);
  const Run pressed = run(scene_file, false, depth_m), deep = run(scene_file, true, depth_m);
  // One stepped force a tick, from the claim's own tick.
  ASSERT_EQ(pressed.force_z.size(), static_cast<std::size_t>(kTicks + 1));
  ASSERT_EQ(deep.force_z.size(), static_cast<std::size_t>(kTicks + 1));
  EXPECT_EQ(pressed.resets, 0) << pressed.first_reset;
  EXPECT_EQ(deep.resets, 0) << deep.first_reset;
  // Settled before the reset and again at the end: the claimed-deep probe holds what the pressed
  // one holds (both are at the same pose; their viscoelastic histories differ by a few percent).
  const double held = mean(pressed.force_z, kResetAt - 50, kResetAt);
  const double held_deep = mean(deep.force_z, kResetAt - 50, kResetAt), held_after_reset = mean(deep.force_z, kTicks - 50, kTicks + 1);
  ASSERT_GT(held, 0.05) << "the pressed probe holds no force";
  EXPECT_NEAR(held_deep / held, 1.0, 0.15);
  EXPECT_NEAR(held_after_reset / held, 1.0, 0.15);
  // On the way: no harder than the press (the tool's whole depth at once would be the contact
  // stiffness x 2 cm, 20 N).
  const double peak = *std::max_element(deep.force_z.begin(), deep.force_z.end());
  const double peak_pressed = *std::max_element(pressed.force_z.begin(), pressed.force_z.begin() + kResetAt);  // before its reset
  EXPECT_LT(peak, 1.2 * peak_pressed);
  std::printf(
      "[ figure ] %s, probe claimed %.0f mm deep and the organ reset under it: peak %.3f N, held %.3f N; "
      "pressed in from above: peak %.3f N, held %.3f N\n",
      scene_file.c_str(), 1e3 * depth_m, peak, held_deep, peak_pressed, held);
}

TEST(ToolEntry, AProbeClaimedInsideTheLiverEntersFromItsSurface) { expect_entered_gently("liver.json"); }
TEST(ToolEntry, AProbeClaimedInsideTheFineLiverEntersFromItsSurface) { expect_entered_gently("liver-12k.json"); }
TEST(ToolEntry, AProbeClaimedDeeperThanTheContactReachesEntersFromItsSurface) { expect_entered_gently("liver.json", kDeeperM); }

}  // namespace
}  // namespace viscera::runtime
