#include "viscera/client/force_slew_limit.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

namespace viscera::client {

protocol::Vector3 ForceSlewLimit::limit(const protocol::Vector3& target, double t_s) {
  const double dt = last_t_ < 0 ? period_ : std::clamp(t_s - last_t_, 0.0, period_);
  last_t_ = t_s;
  const double d[3] = {target[0] - last_[0], target[1] - last_[1], target[2] - last_[2]};
  const double step = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  largest_asked_ = std::max(largest_asked_, step);
  const double allowed = rate_ * dt;
  // Within the limit (an infinite rate allows any step); within rounding of it counts as within, so
  // a ramp ends on its target instead of a step of 1e-16 N after it.
  if (!(step > allowed * (1 + 1e-9))) {
    last_ = target;
    return last_;
  }
  ++limited_;
  const double s = allowed / step;  // along the change, so the direction of the change is kept
  for (int i = 0; i < 3; ++i) last_[i] += s * d[i];
  return last_;
}

}  // namespace viscera::client
