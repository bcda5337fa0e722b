#pragma once  // SPDX-License-Identifier: Apache-2.0
// Fit of L standard linear solids (memory variables) to a constant Q over a frequency band
// (docs/MODEL.md section 3). Relaxation frequencies and weights are both optimised, for the smallest
// largest relative error of Q over the band, so that 3 mechanisms reach about +-17% and 4 about
// +-7% for Q = 4.8 over 0.01-10 Hz (fixed log-spaced placement: about -17%/+36% for 3).
#include <string>
#include <vector>

#include "viscera/tissue/viscoelastic/constant_q.hpp"
#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"

namespace viscera::tissue {

struct ConstantQFit {
  StandardLinearSolids solids;
  double q_min = 0.0, q_max = 0.0;  ///< achieved Q over the band (dense sampling)
  double max_relative_error = 0.0;  ///< max |Q(f)/Q_target - 1| over the band
};

struct ConstantQTarget {
  double q = 4.8;
  double band_low_hz = 0.01, band_high_hz = 10.0;
  int mechanisms = 3;  ///< 1..8
  double modulus_pa = 1e3;  ///< |M| at the reference frequency
  double reference_frequency_hz = 2.0;
  bool optimise_frequencies = true;  ///< false: log-spaced relaxation frequencies, weights only
  /// If not empty: use these relaxation frequencies [rad/s] as they are and fit only the weights
  /// (to give bulk and shear the same frequencies).
  std::vector<double> fixed_frequencies_rad_s;
};

/// Throws InputError naming `source` and the field for Q <= 0, f1 >= f2, L outside 1..8, etc.
ConstantQFit fit_constant_q(const ConstantQTarget& target, const std::string& source = "viscoelasticity");

/// Printable table of the mechanisms and the achieved Q over the band.
std::string describe(const ConstantQFit& fit, const ConstantQTarget& target);

}  // namespace viscera::tissue
