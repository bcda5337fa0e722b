#pragma once
// The simulation server: owns the organ and its solver, runs physics at a fixed rate with a
// deadline-aware loop, takes instrument commands and session requests over DDS, and publishes
// force feedback (with each command's sequence and stamp echoed), the scene state and telemetry.
#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "scene_file.hpp"

namespace viscera::runtime {

struct ServerStats {
  std::uint64_t ticks = 0, rejected = 0, forces_sent = 0;
  std::uint64_t late_ticks = 0;    ///< ticks that ended after their 1/rate slot (the next one starts at once)
  std::uint64_t missed_slots = 0;  ///< slots of the fixed-rate grid that passed with no tick
  std::uint64_t physics_resets = 0;  ///< organ reset to rest after an integration failure
  std::uint64_t mesh_frames = 0, mesh_frames_skipped = 0;  ///< surface frames published; due but replaced
  double step_p50_us = 0, step_p99_us = 0, step_max_us = 0, jitter_p99_us = 0, rate_hz = 0;
};

class SimulationServer {
 public:
  /// scene_dir: where load_scene requests find scenes (empty: the scene file's directory).
  explicit SimulationServer(const SceneSpec& scene, const std::string& scene_dir = {});
  ~SimulationServer();
  /// Runs until `stop` becomes true (or for duration_s > 0). `status` gets a line each second.
  ServerStats run(const std::atomic<bool>& stop, double duration_s, const std::function<void(const std::string&)>& status);
  /// One line describing the loaded scene.
  std::string describe() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscera::runtime
