// The server's figures against their definitions: the rate is ticks per window, the percentiles  // SPDX-License-Identifier: Apache-2.0
// are the sorted samples' elements at rank floor(p (n - 1)), and the telemetry and status line
// carry the counts as they are.
#include "viscera/runtime/server_statistics.hpp"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

namespace viscera::runtime {
namespace {

TEST(ServerStatistics, RateAndPercentilesOfEachWindow) {
  ServerStatistics statistics;
  ServerStats stats;
  std::mt19937_64 rng(5);
  std::vector<double> steps;
  for (int k = 0; k < 1000; ++k) {
    const double step = std::uniform_real_distribution<double>(100, 900)(rng);
    steps.push_back(step);
    statistics.tick(step, 0.5 * step);
    ++stats.ticks;
  }
  statistics.close_window(0.8, stats);
  std::sort(steps.begin(), steps.end());
  EXPECT_DOUBLE_EQ(stats.rate_hz, 1000 / 0.8);
  EXPECT_EQ(stats.step_p50_us, steps[499]);  // rank floor(0.5 x 999)
  EXPECT_EQ(stats.step_p99_us, steps[989]);  // rank floor(0.99 x 999)
  EXPECT_EQ(stats.step_max_us, steps.back());
  EXPECT_EQ(stats.jitter_p99_us, 0.5 * steps[989]);
  // The next window counts only its own ticks.
  for (int k = 0; k < 10; ++k, ++stats.ticks) statistics.tick(1, 1);
  statistics.close_window(1.0, stats);
  EXPECT_DOUBLE_EQ(stats.rate_hz, 10);
  EXPECT_EQ(stats.step_max_us, 1);
}

TEST(ServerStatistics, TelemetryAndStatusCarryTheCounts) {
  ServerStats s;
  s.ticks = 12345;
  s.late_ticks = 7;
  s.missed_slots = 3;
  s.rejected_malformed = 5;
  s.rejected_not_owner = 2;
  s.rejected_unknown_instrument = 1;
  s.rejected_other_participant = 4;
  s.rejected = 12;
  s.rate_hz = 999;
  const auto t = telemetry_report(s, 42);
  EXPECT_EQ(t.server_stamp_ns, 42);
  EXPECT_EQ(t.steps, 12345u);
  EXPECT_EQ(t.late_ticks, 7u);
  EXPECT_EQ(t.missed_slots, 3u);
  EXPECT_EQ(t.rejected_messages, 12u);
  EXPECT_EQ(t.rejected_other_participant, 4u);
  EXPECT_EQ(t.rejected_malformed + t.rejected_not_owner + t.rejected_unknown_instrument + t.rejected_other_participant, t.rejected_messages);
  const std::string line = status_line(s, true, 2, 1.25, 0.12);
  EXPECT_NE(line.find("999 Hz physics (paused)"), std::string::npos) << line;
  EXPECT_NE(line.find("late ticks 7, missed slots 3, 2 instruments in use, |F| 1.250 N, tip strain 0.120, rejected 12 (malformed 5, not owner 2, "
                      "unknown instrument 1, "
                      "another participant's client id 4)"),
            std::string::npos)
      << line;
}

}  // namespace
}  // namespace viscera::runtime
