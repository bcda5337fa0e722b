#include "viscera/recording/playback_clock.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <stdexcept>

namespace viscera::recording {

PlaybackClock::PlaybackClock(std::uint64_t position_ns, double rate, WallTime now) : anchor_ns_(position_ns), anchor_wall_(now), rate_(rate) {
  if (!(rate > 0) || !std::isfinite(rate)) throw std::invalid_argument("playback rate must be > 0");
}

std::uint64_t PlaybackClock::position(WallTime now) const {
  if (paused_ || now <= anchor_wall_) return anchor_ns_;
  const double elapsed_ns = std::chrono::duration<double, std::nano>(now - anchor_wall_).count();
  return anchor_ns_ + static_cast<std::uint64_t>(std::llround(elapsed_ns * rate_));
}

PlaybackClock::WallTime PlaybackClock::due(std::uint64_t t_ns) const {
  if (paused_) return WallTime::max();
  const double ahead_ns = (static_cast<double>(t_ns) - static_cast<double>(anchor_ns_)) / rate_;
  return anchor_wall_ + std::chrono::nanoseconds(std::llround(ahead_ns));
}

void PlaybackClock::pause(WallTime now) {
  if (paused_) return;
  anchor_ns_ = position(now);
  anchor_wall_ = now;
  paused_ = true;
}

void PlaybackClock::resume(WallTime now) {
  if (!paused_) return;
  anchor_wall_ = now;
  paused_ = false;
}

void PlaybackClock::seek(std::uint64_t t_ns, WallTime now) {
  anchor_ns_ = t_ns;
  anchor_wall_ = now;
}

}  // namespace viscera::recording
