#pragma once  // SPDX-License-Identifier: Apache-2.0
// The lockstep harness of the lockstep tests: one SimulationServer in lockstep in this process, its
// endpoints in memory, driven through a script of steps on the bundled liver scene.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/simulation_server.hpp"

#include "memory_endpoints.hpp"

namespace viscera::runtime::testing {

namespace proto = viscera::protocol;

inline constexpr std::uint64_t kFirstTick = 1001;  // a recording's clock: not the server's own 1
inline constexpr double kFirstSimTime = 1.0;
inline constexpr int kTicks = 400;

/// Press down on the organ's top at 1 kHz; change the material at +150, pause at +250 and resume
/// at +260; a frame every 20 ticks. `nudge_at`: the tick whose command is moved by 1 um.
inline std::vector<proto::LockstepStep> script(const proto::Scene& scene, std::uint64_t nudge_at = 0) {
  const double cx = 0.5 * (scene.bounds_min[0] + scene.bounds_max[0]), cy = 0.5 * (scene.bounds_min[1] + scene.bounds_max[1]);
  const double z0 = scene.bounds_max[2] + 0.002;
  std::vector<proto::LockstepStep> steps;
  proto::LockstepStep first;
  first.tick = kFirstTick;
  first.sim_time_s = kFirstSimTime;
  first.requests.push_back(proto::encode(proto::SessionRequest{7, proto::Action::claim_instrument, 1}));
  steps.push_back(first);
  for (int k = 1; k <= kTicks; ++k) {
    proto::LockstepStep s;
    s.tick = kFirstTick + static_cast<std::uint64_t>(k);
    proto::Command c;
    c.instrument_id = 1;
    c.client_id = 7;
    c.seq = static_cast<std::uint64_t>(k);
    c.client_stamp_ns = 1000 * k;
    c.tip_position = {cx, cy, z0 - 0.02 * k / kTicks};
    if (s.tick == nudge_at) c.tip_position[0] += 1e-6;
    s.commands.push_back(proto::encode(c));
    s.answers.push_back(proto::encode(c));
    if (k == 150) {
      proto::SessionRequest r{8, proto::Action::set_material, 0, 1};
      r.material.youngs_modulus_pa = 7000;
      s.requests.push_back(proto::encode(r));
    }
    if (k == 250) s.requests.push_back(proto::encode(proto::SessionRequest{8, proto::Action::pause, 0, 2}));
    if (k == 260) s.requests.push_back(proto::encode(proto::SessionRequest{8, proto::Action::resume, 0, 3}));
    s.want_frame = k % 20 == 0;
    steps.push_back(s);
  }
  return steps;
}

struct LockstepRun {
  std::vector<proto::LockstepResult> results;
  proto::Scene scene;
};

using Script = std::function<std::vector<proto::LockstepStep>(const proto::Scene&)>;

/// One lockstep server on `threads` physics threads, through the steps of `steps_for` (script()),
/// on the bundled liver scene as `adjust` changes it.
inline LockstepRun run(int threads, std::uint64_t nudge_at = 0, const Script& steps_for = {}, const std::function<void(SceneSpec&)>& adjust = {}) {
  SceneSpec spec = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  spec.physics_threads = threads;
  if (adjust) adjust(spec);
  MemoryEndpoints endpoints;
  MemoryLockstepLink link;
  SimulationServer server(spec, endpoints, {}, TickBudget{1e9}, true);  // lockstep: no real time to keep, as viscera-server --lockstep
  LockstepRun r;
  r.scene = endpoints.decoded<proto::Scene>(endpoints.scenes, proto::decode_scene).back();
  std::atomic<bool> stop{false};
  std::thread t([&] { server.run_lockstep(stop, link, {}); });
  const auto steps = steps_for ? steps_for(r.scene) : script(r.scene, nudge_at);
  for (const auto& s : steps) link.push_step(s);
  r.results = link.wait_results(steps.size(), std::chrono::seconds(300));
  stop = true;
  t.join();
  return r;
}

}  // namespace viscera::runtime::testing
