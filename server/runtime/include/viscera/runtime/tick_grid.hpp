#pragma once  // SPDX-License-Identifier: Apache-2.0
// The physics loop's fixed-rate schedule: tick k owns the slot [S_k, S_k + period), and the slots
// follow each other on a grid fixed at the start, so simulated time stays locked to wall time.
//
// A tick that ends inside its slot is followed by the next tick at the next slot's start. A tick
// that ends after its slot (late) is followed at once, and the grid is kept: the next tick then has
// the rest of its own slot, so one late tick costs nothing more when the ticks' median leaves room.
// Only when a whole slot has passed with no tick started in it is that slot missed: the schedule
// skips to the slot that holds the present and never runs ticks in a burst to catch up.
//
// Pure logic on a clock given by the caller (nanoseconds since any epoch), so it is tested with
// made-up times. Not thread-safe; the physics thread owns it.
#include <chrono>
#include <cstdint>
#include <thread>

namespace viscera::runtime {

class TickGrid {
 public:
  using Time = std::chrono::nanoseconds;  ///< since any fixed epoch (the caller's clock)

  /// The first slot starts at `first_slot_start`.
  explicit TickGrid(Time first_slot_start) : slot_start_(first_slot_start) {}

  /// When the tick of the current slot may start: the slot's start.
  Time slot_start() const { return slot_start_; }

  /// The tick of the current slot, whose length is `period`, ended at `now`. Moves to the slot of
  /// the next tick and returns when that tick should start: its slot's start, or `now` when that
  /// has passed. A session may change the period between ticks; the grid then continues from the
  /// end of the slot just finished with the new period.
  Time tick_ended(Time now, Time period) {
    slot_start_ += period;  // the next slot
    if (now <= slot_start_) return slot_start_;
    ++late_;
    // The next slot has begun: start its tick now, unless whole slots have passed meanwhile.
    const auto passed = (now - slot_start_) / period;  // slots that ended with no tick started
    missed_ += static_cast<std::uint64_t>(passed);
    slot_start_ += passed * period;
    return now;
  }

  /// Ticks that ended after their slot's end.
  std::uint64_t late_ticks() const { return late_; }
  /// Slots that passed with no tick (each one period of simulated time behind wall time).
  std::uint64_t missed_slots() const { return missed_; }

 private:
  Time slot_start_;
  std::uint64_t late_ = 0, missed_ = 0;
};

/// How long before a slot the physics thread stops sleeping and waits actively: the scheduler wakes
/// a sleeping thread up to about 150 us late on the 2-vCPU VMs measured (docs/PERFORMANCE.md), which
/// with a 0.9 ms tick (the 12k liver) makes it late.
inline constexpr std::chrono::microseconds kSpinBeforeSlot{200};

/// Waits until `next` on `Clock`: sleeps until kSpinBeforeSlot before it, then yields until it.
template <class Clock>
void wait_for_slot(typename Clock::time_point next) {
  const auto now = Clock::now();
  if (next <= now) return;
  if (const auto early = next - kSpinBeforeSlot; early > now) std::this_thread::sleep_until(early);
  while (Clock::now() < next) std::this_thread::yield();
}

}  // namespace viscera::runtime
