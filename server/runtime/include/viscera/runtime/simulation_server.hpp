#pragma once  // SPDX-License-Identifier: Apache-2.0
// The simulation server: owns the organ and its solver, runs the physics at a fixed rate, takes
// instrument commands and session requests from its endpoints (DDS in viscera-server) and
// publishes forces (each command's sequence and stamp echoed), the scene state, events, telemetry
// and surface frames. It composes parts with one job each: the instrument table (ownership and
// the lease), the simulated tools (motion, grasp, contact events), the command responder (the
// immediate answers), session control (scenes and materials built in the background), the
// statistics, and the fixed-rate grid (tick_grid.hpp).
#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/server_endpoints.hpp"
#include "viscera/runtime/server_statistics.hpp"
#include "viscera/runtime/tick_budget.hpp"

namespace viscera::runtime {

class SimulationServer {
 public:
  /// scene_dir: where load_scene requests find scenes (empty: the scene file's directory). A scene,
  /// material or physics rate whose tick would not fit `budget` is refused (tick_budget.hpp).
  /// `endpoints` must outlive the server. A `lockstep` server is run with run_lockstep().
  SimulationServer(const SceneSpec& scene, ServerEndpoints& endpoints, const std::string& scene_dir = {}, const TickBudget& budget = {},
                   bool lockstep = false);
  ~SimulationServer();
  /// Runs until `stop` becomes true (or for duration_s > 0). `status` gets a line each second. A
  /// tick checks `stop` between its sub-steps, so a stop is seen within one sub-step.
  ServerStats run(const std::atomic<bool>& stop, double duration_s, const std::function<void(const std::string&)>& status);
  /// Lockstep (docs/RECORDING.md): no wall clock. Each step from `link` runs one tick: its answers
  /// on the state the last tick left, its session requests, its commands as the instruments'
  /// newest, the step; a scene or material asked for is built before the tick goes on, and no
  /// lease runs out. Forces and events go into the step's result (with the surface if asked),
  /// not onto their streams. The first step sets the tick number and the simulated time. Runs
  /// until `stop`.
  ServerStats run_lockstep(const std::atomic<bool>& stop, LockstepLink& link, const std::function<void(const std::string&)>& status);
  /// One line describing the loaded scene.
  std::string describe() const;
  /// Organs still being built or destroyed in the background when a server was destroyed: they
  /// were left to finish on their own threads, and the program should end with std::quick_exit.
  static int abandoned_work();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscera::runtime
