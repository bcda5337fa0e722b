// The physics loop's schedule against what a fixed 1 kHz grid means, worked out by hand for each  // SPDX-License-Identifier: Apache-2.0
// case, and over long runs of made-up tick costs against the grid's two invariants: no tick starts
// before its slot (no bursts), and every slot that has ended holds a tick or is counted missed.
#include "viscera/runtime/tick_grid.hpp"

#include <random>

#include <gtest/gtest.h>

namespace viscera::runtime {
namespace {

using std::chrono::microseconds;
using std::chrono::nanoseconds;
constexpr nanoseconds P = microseconds(1000);

TEST(TickGrid, TicksThatEndInTheirSlotStartOnTheGrid) {
  const nanoseconds t0 = microseconds(5000);
  TickGrid grid(t0);
  EXPECT_EQ(grid.slot_start(), t0);
  // Tick k starts at t0 + k P and ends anywhere inside its slot, even exactly at its end.
  const int ends_us[] = {1, 600, 999, 1000, 250};
  for (int k = 0; k < 5; ++k) {
    const nanoseconds start = t0 + k * P;
    EXPECT_EQ(grid.tick_ended(start + microseconds(ends_us[k]), P), t0 + (k + 1) * P) << "tick " << k;
  }
  EXPECT_EQ(grid.late_ticks(), 0u);
  EXPECT_EQ(grid.missed_slots(), 0u);
}

TEST(TickGrid, ALateTickIsFollowedAtOnceAndTheGridIsKept) {
  TickGrid grid(nanoseconds(0));
  // Tick 0 ends 300 us after its slot: tick 1 starts at once, in its own slot [P, 2P).
  EXPECT_EQ(grid.tick_ended(microseconds(1300), P), microseconds(1300));
  EXPECT_EQ(grid.slot_start(), P);
  EXPECT_EQ(grid.late_ticks(), 1u);
  EXPECT_EQ(grid.missed_slots(), 0u);
  // Tick 1 takes 600 us and ends at 1.9 ms, inside its slot: tick 2 starts on the grid at 2 ms,
  // not 1 ms after tick 1 started (the schedule did not move back by the 300 us).
  EXPECT_EQ(grid.tick_ended(microseconds(1900), P), 2 * P);
  EXPECT_EQ(grid.late_ticks(), 1u);
}

TEST(TickGrid, AStallSkipsTheSlotsThatPassedWithoutABurst) {
  TickGrid grid(nanoseconds(0));
  // Tick 0 stalls until 3.5 ms: slots [1, 2) and [2, 3) ms passed with no tick; tick 3 starts now.
  EXPECT_EQ(grid.tick_ended(microseconds(3500), P), microseconds(3500));
  EXPECT_EQ(grid.slot_start(), 3 * P);
  EXPECT_EQ(grid.missed_slots(), 2u);
  EXPECT_EQ(grid.late_ticks(), 1u);
  // A short tick 3 is followed on the grid at 4 ms: no run of ticks to make up the missed ones.
  EXPECT_EQ(grid.tick_ended(microseconds(3700), P), 4 * P);
  // A tick that ends exactly when the slot after next begins has let one slot pass.
  EXPECT_EQ(grid.tick_ended(6 * P, P), 6 * P);
  EXPECT_EQ(grid.missed_slots(), 3u);
  EXPECT_EQ(grid.late_ticks(), 2u);
}

TEST(TickGrid, AChangedPeriodContinuesFromTheEndOfTheSlotJustFinished) {
  TickGrid grid(nanoseconds(0));
  EXPECT_EQ(grid.tick_ended(microseconds(400), P), P);
  EXPECT_EQ(grid.tick_ended(microseconds(1400), P), 2 * P);
  // From 2 ms on the session runs at 2 kHz: slots [2, 2.5), [2.5, 3) ms...
  const nanoseconds half = P / 2;
  EXPECT_EQ(grid.tick_ended(microseconds(2300), half), microseconds(2500));
  EXPECT_EQ(grid.tick_ended(microseconds(2700), half), microseconds(3000));
  // ...the tick of [3, 3.5) ends at 3.8 ms, inside the next slot: late, but no slot passed...
  EXPECT_EQ(grid.tick_ended(microseconds(3800), half), microseconds(3800));
  EXPECT_EQ(grid.slot_start(), microseconds(3500));
  EXPECT_EQ(grid.missed_slots(), 0u);
  // ...and the tick of [3.5, 4) ends at 4.7 ms: [4, 4.5) passed, its successor runs in [4.5, 5).
  EXPECT_EQ(grid.tick_ended(microseconds(4700), half), microseconds(4700));
  EXPECT_EQ(grid.slot_start(), microseconds(4500));
  EXPECT_EQ(grid.missed_slots(), 1u);
  EXPECT_EQ(grid.late_ticks(), 2u);
}

// A loop as the server runs it, with made-up tick costs: it waits for the start the grid gives,
// then the tick takes its cost. Returns the number of ticks run before `horizon`.
struct LoopRun {
  std::uint64_t ticks = 0;
  TickGrid grid{nanoseconds(0)};
};

template <class Cost>
LoopRun run_until(nanoseconds horizon, Cost&& cost) {
  LoopRun r;
  nanoseconds start = r.grid.slot_start();
  for (;;) {
    // Invariant 1: a tick never starts before its slot (no tick runs ahead to catch up).
    EXPECT_GE(start, r.grid.slot_start());
    EXPECT_LT(start, r.grid.slot_start() + P);  // and it starts within its slot
    const nanoseconds end = start + cost(r.ticks);
    if (end > horizon) break;
    ++r.ticks;
    start = r.grid.tick_ended(end, P);
    // Invariant 2: every slot that has begun holds a tick or was counted missed.
    EXPECT_EQ(r.ticks + r.grid.missed_slots(), static_cast<std::uint64_t>(r.grid.slot_start() / P));
  }
  return r;
}

TEST(TickGrid, OccasionalLateTicksLoseNoSlotWhenTheMedianLeavesRoom) {
  // 600 us ticks, every tenth 1300 us: each late tick is absorbed by the next one's 400 us of room.
  const LoopRun r = run_until(microseconds(10'000'000), [](std::uint64_t k) { return microseconds(k % 10 == 9 ? 1300 : 600); });
  EXPECT_EQ(r.grid.missed_slots(), 0u);
  EXPECT_EQ(r.ticks, 10'000u - 1);  // the last tick would end after the horizon
  EXPECT_EQ(r.grid.late_ticks(), 999u);
}

TEST(TickGrid, RandomTickCostsKeepTheGridAndCountWhatIsLost) {
  // Costs from a heavy-tailed mix: mostly 500-800 us, 2% at 1-3 ms (a stalled core).
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> body(500, 800), tail(1000, 3000);
  std::bernoulli_distribution stall(0.02);
  const LoopRun r = run_until(microseconds(20'000'000), [&](std::uint64_t) { return microseconds(stall(rng) ? tail(rng) : body(rng)); });
  EXPECT_GT(r.grid.late_ticks(), 0u);
  EXPECT_GT(r.grid.missed_slots(), 0u);
  // Stalls of 1-3 ms can pass at most two whole slots each.
  EXPECT_LE(r.grid.missed_slots(), 2 * r.grid.late_ticks());
}

TEST(TickGrid, TicksLongerThanThePeriodRunBackToBackAtTheRateTheyAllow) {
  // Every tick takes 2.5 periods: the loop runs them back to back, 400 per second, and counts the
  // 600 other slots of each second missed.
  const LoopRun r = run_until(microseconds(1'000'000), [](std::uint64_t) { return microseconds(2500); });
  EXPECT_EQ(r.ticks, 400u);
  EXPECT_EQ(r.grid.late_ticks(), 400u);
  EXPECT_EQ(r.grid.missed_slots() + r.ticks, 1000u);
}

}  // namespace
}  // namespace viscera::runtime
