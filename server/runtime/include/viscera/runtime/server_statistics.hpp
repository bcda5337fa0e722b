#pragma once  // SPDX-License-Identifier: Apache-2.0
// The server's figures: ticks, late ticks and missed slots, the step time's and the wake-up
// jitter's percentiles over each reporting window (about a second), rejected messages by reason,
// forces sent, mesh frames. From them the telemetry report and the one-line status.
#include <cstdint>
#include <string>
#include <vector>

#include "viscera/protocol/messages.hpp"

namespace viscera::runtime {

struct ServerStats {
  std::uint64_t ticks = 0, rejected = 0, forces_sent = 0;
  /// rejected, by reason: failed verification; from a client that does not own the instrument;
  /// naming an instrument the scene does not have; naming a client id another DDS participant
  /// holds (ClientBinding)
  std::uint64_t rejected_malformed = 0, rejected_not_owner = 0, rejected_unknown_instrument = 0, rejected_other_participant = 0;
  std::uint64_t late_ticks = 0;  ///< ticks that ended after their 1/rate slot (the next one starts at once)
  std::uint64_t missed_slots = 0;  ///< slots of the fixed-rate grid that passed with no tick
  std::uint64_t physics_resets = 0;  ///< organ reset to rest after an integration failure
  /// Sweeps of a scalpel that changed the mesh, those at which the organ's kinetic plus elastic
  /// energy rose (SweepOutcome::energy_rose), and the largest change of that energy at one [J]
  /// (0 before the first)
  std::uint64_t cut_changes = 0, cut_energy_rises = 0;
  double cut_energy_change_max_j = 0;
  std::uint64_t mesh_frames = 0, mesh_frames_skipped = 0;  ///< surface frames published; due but replaced
  double step_p50_us = 0, step_p99_us = 0, step_max_us = 0, jitter_p99_us = 0, rate_hz = 0;
};

/// Collects each tick's step time and wake-up jitter; closing a window sets the rate and the
/// percentiles of `stats` and starts the next window.
class ServerStatistics {
 public:
  void tick(double step_us, double jitter_us);
  void close_window(double seconds, ServerStats& stats);

 private:
  std::vector<double> step_us_, jitter_us_;
  std::uint64_t ticks_at_window_ = 0;
};

protocol::TelemetryReport telemetry_report(const ServerStats& s, std::int64_t stamp_ns);
/// The status line: rate (and "paused"), step and jitter percentiles, late ticks and missed slots,
/// instruments in use, the largest force on a tool [N] and the largest tissue strain at one (the
/// strain a trainer scores, docs/TRAINING.md; 0 with none in contact), rejections by reason,
/// resets, mesh frames.
std::string status_line(const ServerStats& s, bool paused, int instruments_in_use, double max_force_n, double max_tip_strain);

}  // namespace viscera::runtime
