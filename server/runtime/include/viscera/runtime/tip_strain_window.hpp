#pragma once  // SPDX-License-Identifier: Apache-2.0
// The strain at an instrument (Force.tip_strain), spread over the ticks of a window: one tissue
// strain average over the scene's strain radius (tissue::BallStrain) costs 86 us on the 12k liver
// (786 tetrahedra in a 2 cm ball, docs/PERFORMANCE.md), too much for every tick of the physics
// thread. So each window of n ticks (20 ms) fixes the ball at the point the instrument touched when
// it began, and each of its ticks averages every n-th of the ball's tetrahedra, on that tick's
// positions; at the window's end the sums give the strain, which the forces carry until the next
// window ends. The first tick of a contact computes the whole ball at once (so that no force in
// contact says 0). Deterministic: it depends on the ticks alone, so a session re-simulates it bit
// for bit.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "viscera/tissue/element/ball_strain.hpp"

namespace viscera::runtime {

class TipStrainWindow {
 public:
  /// After a tick: the instrument touches the tissue at `rest_point` (a point of the rest shape), or
  /// not (nullopt); a new window lasts `ticks_per_window` ticks. Returns the strain its force carries.
  double after_tick(const tissue::BallStrain& ball, std::span<const tissue::Vec3> x, const std::optional<tissue::Vec3>& rest_point,
                    std::size_t ticks_per_window);
  double value() const { return value_; }

 private:
  bool touching_ = false;
  std::size_t phase_ = 0, window_ = 1;
  std::vector<std::size_t> elements_;
  double strain_volume_ = 0.0, volume_ = 0.0, value_ = 0.0;
};

/// Ticks of a 20 ms window at `rate_hz` (at least one).
std::size_t tip_strain_window_ticks(double rate_hz);

}  // namespace viscera::runtime
