#pragma once  // SPDX-License-Identifier: Apache-2.0
// Where a replay is in its recording: recording time runs at `rate` times wall time from where it
// was started or sought, and stands still while paused. No clock of its own: the caller passes
// the wall time (steady clock), so tests run it on made-up time.
#include <chrono>
#include <cstdint>

namespace viscera::recording {

class PlaybackClock {
 public:
  using WallTime = std::chrono::steady_clock::time_point;
  /// Recording time `position_ns` at wall time `now`, running at `rate` (> 0).
  PlaybackClock(std::uint64_t position_ns, double rate, WallTime now);
  /// The recording time at wall time `now`.
  std::uint64_t position(WallTime now) const;
  /// When recording time `t_ns` comes (WallTime::max() while paused); past for a time passed.
  WallTime due(std::uint64_t t_ns) const;
  void pause(WallTime now);
  void resume(WallTime now);
  /// Jumps to recording time `t_ns`; paused stays paused.
  void seek(std::uint64_t t_ns, WallTime now);
  bool paused() const { return paused_; }
  double rate() const { return rate_; }

 private:
  std::uint64_t anchor_ns_;  // recording time at wall time anchor_wall_
  WallTime anchor_wall_;
  double rate_;
  bool paused_ = false;
};

}  // namespace viscera::recording
