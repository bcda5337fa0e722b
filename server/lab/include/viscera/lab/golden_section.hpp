#pragma once  // SPDX-License-Identifier: Apache-2.0
// Golden-section search for the minimum of a unimodal function of one variable: the interval
// shrinks by the golden ratio per evaluation. Used for every nonlinear parameter the lab fits.
#include <cmath>
#include <functional>

namespace viscera::lab {

struct Minimum {
  double x, f;
};

/// The minimum of `f` on [lo, hi], to `tolerance` in x or after `max_iterations` evaluations.
inline Minimum golden_section(const std::function<double(double)>& f, double lo, double hi, double tolerance, int max_iterations = 40) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < max_iterations && hi - lo > tolerance; ++it) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  return f1 < f2 ? Minimum{x1, f1} : Minimum{x2, f2};
}

}  // namespace viscera::lab
