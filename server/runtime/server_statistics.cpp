#include "viscera/runtime/server_statistics.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cstdio>

#include "viscera/common/percentile.hpp"

namespace viscera::runtime {

void ServerStatistics::tick(double step_us, double jitter_us) {
  step_us_.push_back(step_us);
  jitter_us_.push_back(jitter_us);
}

void ServerStatistics::close_window(double seconds, ServerStats& stats) {
  stats.rate_hz = static_cast<double>(stats.ticks - ticks_at_window_) / seconds;
  stats.step_p50_us = common::percentile(step_us_, 0.5);
  stats.step_p99_us = common::percentile(step_us_, 0.99);
  stats.step_max_us = step_us_.empty() ? 0.0 : *std::max_element(step_us_.begin(), step_us_.end());
  stats.jitter_p99_us = common::percentile(jitter_us_, 0.99);
  step_us_.clear();
  jitter_us_.clear();
  ticks_at_window_ = stats.ticks;
}

protocol::TelemetryReport telemetry_report(const ServerStats& s, std::int64_t stamp_ns) {
  return {stamp_ns,
          s.ticks,
          s.late_ticks,
          s.rejected,
          s.rate_hz,
          s.step_p50_us,
          s.step_p99_us,
          s.step_max_us,
          s.jitter_p99_us,
          s.missed_slots,
          s.rejected_malformed,
          s.rejected_not_owner,
          s.rejected_unknown_instrument,
          s.rejected_other_participant};
}

std::string status_line(const ServerStats& s, bool paused, int instruments_in_use, double max_force_n, double max_tip_strain) {
  char line[500];
  using ull = unsigned long long;
  std::snprintf(line, sizeof line,
                "%.0f Hz physics%s, step p50 %.0f us p99 %.0f us max %.0f us, jitter p99 %.0f us, late ticks %llu, missed slots %llu, "
                "%d instruments in use, |F| %.3f N, tip strain %.3f, rejected %llu (malformed %llu, not owner %llu, unknown instrument %llu, another "
                "participant's "
                "client id %llu), physics resets %llu, "
                "mesh frames %llu (%llu skipped)",
                s.rate_hz, paused ? " (paused)" : "", s.step_p50_us, s.step_p99_us, s.step_max_us, s.jitter_p99_us, ull(s.late_ticks),
                ull(s.missed_slots), instruments_in_use, max_force_n, max_tip_strain, ull(s.rejected), ull(s.rejected_malformed),
                ull(s.rejected_not_owner), ull(s.rejected_unknown_instrument), ull(s.rejected_other_participant), ull(s.physics_resets),
                ull(s.mesh_frames), ull(s.mesh_frames_skipped));
  return line;
}

}  // namespace viscera::runtime
