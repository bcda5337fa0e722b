// The client's phase lock to the server's physics ticks (client-sdk tick_phase.hpp), against a  // SPDX-License-Identifier: Apache-2.0
// simulated server: ticks at a fixed rate whose ends jitter, seen by a loop that starts at any phase.
#include "viscera/client/tick_phase.hpp"

#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include <gtest/gtest.h>

using viscera::client::TickPhase;
using namespace std::chrono_literals;

namespace {

constexpr std::int64_t kMs = 1'000'000;

// The end of the newest tick at or before `t_ns`: ticks start every `period_ns` from 0 and take
// 550-750 us (a deterministic pseudo-random sequence).
std::int64_t last_tick_end(std::int64_t t_ns, std::int64_t period_ns) {
  for (std::int64_t k = t_ns / period_ns; k >= 0; --k) {
    const std::int64_t end = k * period_ns + 550'000 + (k * 7919 % 201) * 1'000;
    if (end <= t_ns) return end;
  }
  return -1;
}

}  // namespace

TEST(TickPhase, ErrorIsTheSignedDistanceToTheNearestTargetWithinHalfAPeriod) {
  const TickPhase phase(1ms, 100us);
  const std::int64_t end = 5'000'000'000;  // any epoch; targets at end + 0.1 ms + k ms
  EXPECT_EQ(phase.error(end + 100'000, end).count(), 0);
  EXPECT_EQ(phase.error(end + 100'000 + 7 * kMs, end).count(), 0);
  EXPECT_EQ(phase.error(end + 130'000, end).count(), 30'000);
  EXPECT_EQ(phase.error(end + 70'000, end).count(), -30'000);
  EXPECT_EQ(phase.error(end + 100'000 - 3 * kMs + 20'000, end).count(), 20'000);  // before the tick
  EXPECT_EQ(phase.error(end + 100'000 + 600'000, end).count(), -400'000);  // nearer the next target
  EXPECT_EQ(phase.error(end + 100'000 + 500'000, end).count(), -500'000);  // half a period: [-P/2, P/2)
  EXPECT_EQ(phase.error(end + 100'000 + 499'999, end).count(), 499'999);
}

TEST(TickPhase, CorrectionIsAnEighthOfTheErrorAndBounded) {
  const TickPhase phase(1ms, 0us, 20us);
  EXPECT_EQ(phase.correction(80'000, 0).count(), -10'000);
  EXPECT_EQ(phase.correction(-80'000, 0).count(), 10'000);
  EXPECT_EQ(phase.correction(400'000, 0).count(), -20'000);  // bounded
  EXPECT_EQ(phase.correction(0, 0).count(), 0);
  EXPECT_THROW(TickPhase(0ns, 0ns), std::invalid_argument);
}

TEST(TickPhase, LocksALoopStartedAtAnyPhaseAndKeepsItsRate) {
  for (std::int64_t server_period : {kMs, kMs + 500}) {  // the server's clock the same, or 500 ppm slow
    for (std::int64_t start : {0LL, 123'456LL, 500'000LL, 999'999LL}) {
      const TickPhase phase(1ms, 100us, 20us);
      std::int64_t next = 10 * kMs + start;
      const int periods = 4000;
      std::int64_t half = 0;  // the loop's time half way, once locked
      std::int64_t largest_late_error = 0;
      for (int k = 0; k < periods; ++k) {
        next += kMs;
        const std::int64_t end = last_tick_end(next, server_period);
        const std::int64_t c = phase.correction(next, end).count();
        ASSERT_LE(std::abs(c), 20'000);
        next += c;
        if (k == periods / 2) half = next;
        if (k > periods / 2) {
          // Locked: the loop runs after the newest tick's end, within the ticks' own jitter
          // (their ends spread over 200 us) of the target 100 us after it.
          const std::int64_t e = phase.error(next, last_tick_end(next, server_period)).count();
          largest_late_error = std::max(largest_late_error, std::abs(e));
        }
      }
      EXPECT_LT(largest_late_error, 150'000) << "start " << start << ", server period " << server_period;
      // Locked, the loop's mean period is the server's (500 ppm apart from its own: 500 ns).
      const auto counted = periods - 1 - periods / 2;  // the periods from the half-way index to the last
      const double mean_period = static_cast<double>(next - half) / static_cast<double>(counted);
      EXPECT_NEAR(mean_period, static_cast<double>(server_period), 50.0) << "start " << start;
    }
  }
}
