#pragma once  // SPDX-License-Identifier: Apache-2.0
// Keeps a client's periodic loop (a haptic device at the server's physics rate) at a fixed phase
// after the server's physics ticks, so that its command, the server's immediate answer and the
// network threads on both sides run in the server's idle time between ticks, and every tick takes
// a command of the same age (the rest of the period after the tick and the offset) instead of
// anywhere from 0 to a period. Measured on the 12k liver (docs/PERFORMANCE.md, "what a connected
// client costs the 12k tick"): round trip p99 about a tenth lower, median tick a little shorter,
// late ticks unchanged.
//
// The server stamps each force it publishes after a tick (Force::step_time_ns > 0) with its clock
// (Force::server_stamp_ns, DDS time). The client compares that with its own DDS time: exact on one
// host; across hosts the offset between their clocks shifts the phase (no worse than running free).
//
//   viscera::client::TickPhase phase(period, std::chrono::microseconds(100));
//   next += period;
//   if (const auto end = client.last_tick_end_ns(instrument)) next += phase.correction(next_in_dds_time, *end);
#include <chrono>
#include <cstdint>

namespace viscera::client {

class TickPhase {
 public:
  /// `period`: the loop's period, equal to the server's tick; `offset`: where in the period to run,
  /// after the end of a tick; `max_step`: the largest correction per period (keeps the device rate
  /// within a few percent while the phase moves).
  TickPhase(std::chrono::nanoseconds period, std::chrono::nanoseconds offset, std::chrono::nanoseconds max_step = std::chrono::microseconds(20));

  /// The signed distance of `next_ns` from the nearest target time (a tick's end plus the offset,
  /// plus whole periods), in [-period/2, period/2). Both on the same clock [ns].
  std::chrono::nanoseconds error(std::int64_t next_ns, std::int64_t tick_end_ns) const;
  /// What to add to the loop's next time: an eighth of -error, at most max_step either way.
  std::chrono::nanoseconds correction(std::int64_t next_ns, std::int64_t tick_end_ns) const;

 private:
  std::int64_t period_ns_, offset_ns_, max_step_ns_;
};

}  // namespace viscera::client
