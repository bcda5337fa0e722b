#pragma once  // SPDX-License-Identifier: Apache-2.0
// A lab's test follows a command that is piecewise linear in time (ramps, holds, triangles), but
// its changes of slope fall between samples. Taken as linear from sample to sample, a ramp that
// starts between two samples gets a slope that is neither the hold's nor the ramp's, and a
// Kelvin-Voigt solid's viscous stress (eta times the rate) is wrong by up to its whole jump there.
// command_path() restores the corners: where the interval before a sample mixes two slopes and the
// interval after it is clean (agrees with the next one), the corner is put where the line before
// meets the line after. A test that starts already moving, on a line that reaches zero less than
// one interval before its first sample, starts from rest there. Every model and the tetrahedral
// specimen run along this path, so they all see the same history.
#include <cstddef>
#include <vector>

namespace viscera::lab {

struct CommandPath {
  std::vector<double> time_s, value;  ///< the samples and the corners restored between them
  std::vector<std::size_t> sample;  ///< sample k is point sample[k] of the path
  /// The rate at sample k: the slope of the path's piece that ends there (0 at the path's start).
  double rate_at_sample(std::size_t k) const;
  /// The value at time t (linear between points; constant outside).
  double at(double t) const;
};

CommandPath command_path(const std::vector<double>& time_s, const std::vector<double>& value);

}  // namespace viscera::lab
