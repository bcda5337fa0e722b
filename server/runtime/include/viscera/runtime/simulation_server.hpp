#pragma once
// The simulation server: owns the organ and its solver, runs physics at a fixed rate with a
// deadline-aware loop, takes instrument commands and session requests over DDS, and publishes
// force feedback (with each command's sequence and stamp echoed), the scene state and telemetry.
#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/tick_budget.hpp"

namespace viscera::runtime {

struct ServerStats {
  std::uint64_t ticks = 0, rejected = 0, forces_sent = 0;
  /// rejected, by reason: failed verification; from a client that does not own the instrument;
  /// naming an instrument the scene does not have
  std::uint64_t rejected_malformed = 0, rejected_not_owner = 0, rejected_unknown_instrument = 0;
  std::uint64_t late_ticks = 0;    ///< ticks that ended after their 1/rate slot (the next one starts at once)
  std::uint64_t missed_slots = 0;  ///< slots of the fixed-rate grid that passed with no tick
  std::uint64_t physics_resets = 0;  ///< organ reset to rest after an integration failure
  std::uint64_t mesh_frames = 0, mesh_frames_skipped = 0;  ///< surface frames published; due but replaced
  double step_p50_us = 0, step_p99_us = 0, step_max_us = 0, jitter_p99_us = 0, rate_hz = 0;
};

class SimulationServer {
 public:
  /// scene_dir: where load_scene requests find scenes (empty: the scene file's directory). A scene,
  /// material or physics rate whose tick would not fit `budget` is refused (tick_budget.hpp).
  explicit SimulationServer(const SceneSpec& scene, const std::string& scene_dir = {}, const TickBudget& budget = {});
  ~SimulationServer();
  /// Runs until `stop` becomes true (or for duration_s > 0). `status` gets a line each second. A
  /// tick checks `stop` between its sub-steps, so a stop is seen within one sub-step.
  ServerStats run(const std::atomic<bool>& stop, double duration_s, const std::function<void(const std::string&)>& status);
  /// One line describing the loaded scene.
  std::string describe() const;
  /// Organs still being built or destroyed in the background when the server was destroyed: they
  /// were left to finish on their own threads, and the program should end with std::quick_exit.
  static int abandoned_work();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscera::runtime
