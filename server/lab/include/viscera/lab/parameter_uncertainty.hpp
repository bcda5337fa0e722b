#pragma once  // SPDX-License-Identifier: Apache-2.0
// How well the data determine a fitted model's parameters: a bootstrap over tests. The tests are
// drawn with replacement (as many as the data set holds), the model's structure (its mechanisms,
// forms and relaxation times) is fitted again to each draw, and each parameter's spread over the
// draws is its standard error, its 2.5% and 97.5% quantiles a 95% interval. Tests are the unit
// because a test's samples are not independent of one another (a misfit runs through a whole ramp
// or hold), and because the specimens of different tests differ as real specimens do: a spread
// over tests is the one a second laboratory would see. With fewer than three tests there is no
// spread to draw from, and the report says so.
#include <string>
#include <vector>

#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

/// A parameter is said not to be determined by the data when its standard error is more than
/// this share of its value, or when it is a modulus or viscosity that some draws fit as zero.
inline constexpr double kUndeterminedShare = 0.5;

struct ParameterEstimate {
  std::string name, unit;  ///< e.g. "E", "Pa"; "E_l (tau 0.1 s)", "Pa"
  double value = 0.0;  ///< fitted to all tests
  double standard_error = 0.0;  ///< the SD over the draws
  double low = 0.0, high = 0.0;  ///< 2.5% and 97.5% quantiles over the draws
  bool determined = true;  ///< standard_error <= kUndeterminedShare |value|, and a positive modulus's interval above zero
};

struct ParameterUncertainty {
  std::string method;  ///< how the figures were found
  int replicates = 0;  ///< draws fitted
  /// Draws whose fit chose the same stiffening form (B is compared only within one form, and its
  /// figures come from those draws); equal to replicates without stiffening.
  int same_form = 0;
  std::string not_run;  ///< why there are no figures ("" when there are)
  std::vector<ParameterEstimate> parameters;
};

/// The parameters of a model by name and unit, in a fixed order: E, eta, then those of its
/// mechanisms (B, r, d, one E_l per relaxation time).
std::vector<ParameterEstimate> parameters_of(const MaterialModel& m);

/// The bootstrap over `d`'s tests of `fitted` (fitted to all of them), `replicates` draws from a
/// generator seeded with `seed` (the same figures for the same data).
ParameterUncertainty bootstrap_over_tests(const MaterialModel& fitted, const Dataset& d, int replicates, unsigned seed = 1);

}  // namespace viscera::lab
