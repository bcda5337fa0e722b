#include "viscera/runtime/tip_strain_window.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

namespace viscera::runtime {

double TipStrainWindow::after_tick(const tissue::BallStrain& ball, std::span<const tissue::Vec3> x, const std::optional<tissue::Vec3>& rest_point,
                                   std::size_t ticks_per_window) {
  if (!rest_point) {
    touching_ = false;
    phase_ = 0;
    value_ = 0.0;
    return value_;
  }
  if (!touching_) {  // a contact begins: the whole ball now
    touching_ = true;
    phase_ = 0;
    value_ = ball.at(x, *rest_point).strain;
    return value_;
  }
  if (phase_ == 0) {
    window_ = std::max<std::size_t>(ticks_per_window, 1);
    ball.elements_near(*rest_point, elements_);
    strain_volume_ = volume_ = 0.0;
  }
  const auto share = ball.sum_over(x, elements_, phase_, window_);
  strain_volume_ += share.strain_volume_m3;
  volume_ += share.volume_m3;
  if (++phase_ == window_) {
    phase_ = 0;
    if (volume_ > 0) value_ = strain_volume_ / volume_;
  }
  return value_;
}

std::size_t tip_strain_window_ticks(double rate_hz) { return static_cast<std::size_t>(std::max(1.0, std::round(rate_hz * 0.02))); }

}  // namespace viscera::runtime
