#include "viscera/client/tick_phase.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <stdexcept>

namespace viscera::client {

TickPhase::TickPhase(std::chrono::nanoseconds period, std::chrono::nanoseconds offset, std::chrono::nanoseconds max_step)
    : period_ns_(period.count()), offset_ns_(offset.count()), max_step_ns_(max_step.count()) {
  if (period_ns_ <= 0) throw std::invalid_argument("TickPhase: the period must be positive");
  if (max_step_ns_ < 0) throw std::invalid_argument("TickPhase: the largest correction must not be negative");
}

std::chrono::nanoseconds TickPhase::error(std::int64_t next_ns, std::int64_t tick_end_ns) const {
  std::int64_t e = (next_ns - tick_end_ns - offset_ns_) % period_ns_;  // in (-period, period)
  if (e < 0) e += period_ns_;
  if (e >= period_ns_ - period_ns_ / 2) e -= period_ns_;  // [-period/2, period/2)
  return std::chrono::nanoseconds(e);
}

std::chrono::nanoseconds TickPhase::correction(std::int64_t next_ns, std::int64_t tick_end_ns) const {
  const std::int64_t c = -error(next_ns, tick_end_ns).count() / 8;
  return std::chrono::nanoseconds(std::clamp(c, -max_step_ns_, max_step_ns_));
}

}  // namespace viscera::client
