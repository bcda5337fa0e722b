#pragma once  // SPDX-License-Identifier: Apache-2.0
// A re-simulation compared with its recording, tick by tick: every recorded force (all its
// physics: contact, force, torque, contact point and normal, penetration, the organ's largest edge strain; not the wall-clock
// stamps), every server event (kind, instrument, client, request, simulated time), every surface
// frame (positions to the bit) against what the lockstep server computed. The first divergence is
// named: tick, topic, field, recorded and recomputed values. No network: the driver feeds it the
// results.
//
// The local stiffness is counted apart, not as a divergence: a live server falls back to the
// contact penalty until its compliance worker has a node's block, when that happens depends on
// the machine's timing, and the lockstep server always waits for it.
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "viscera/recording/lockstep_plan.hpp"

namespace viscera::recording {

struct Divergence {
  std::uint64_t tick = 0;
  std::string topic;  ///< force_feedback | event | mesh_frame | lockstep
  std::string what;  ///< which message ("instrument 1, command 42, stepped")
  std::string field, recorded, recomputed;
};

struct ResimulationCounts {
  std::uint64_t ticks = 0;
  std::uint64_t forces_compared = 0, forces_identical = 0, forces_not_reproduced = 0, forces_not_recorded = 0, stiffness_differences = 0;
  std::uint64_t events_compared = 0, events_identical = 0;
  std::uint64_t frames_compared = 0, frames_identical = 0;
};

class ResimulationCheck {
 public:
  /// `recording` is read again only to name a diverging frame's vertex.
  ResimulationCheck(const LockstepPlan& plan, Recording& recording) : plan_(plan), recording_(recording) {}
  /// One tick's result.
  void check(const protocol::LockstepResult& result);
  const std::optional<Divergence>& first_divergence() const { return first_; }
  const ResimulationCounts& counts() const { return counts_; }
  /// Every recorded force, event and frame reproduced to the bit, and nothing diverged.
  bool identical() const;
  /// The report (docs/RECORDING.md): counts, verdict, first divergence, the plan's notes.
  nlohmann::json report() const;

 private:
  void diverged(Divergence d);
  void check_forces(const protocol::LockstepResult& r);
  void check_events(const protocol::LockstepResult& r);
  void check_frame(const protocol::LockstepResult& r);

  const LockstepPlan& plan_;
  Recording& recording_;
  ResimulationCounts counts_;
  std::optional<Divergence> first_;
};

}  // namespace viscera::recording
