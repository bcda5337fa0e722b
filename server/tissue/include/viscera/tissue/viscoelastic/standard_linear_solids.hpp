#pragma once  // SPDX-License-Identifier: Apache-2.0
// L standard linear solids in parallel, written with memory variables (Emmerich & Korn 1987;
// docs/MODEL.md section 3):
//     sigma = M_U (eps - sum_l Y_l zeta_l),   d zeta_l / dt = w_l (eps - zeta_l).
// Complex modulus M(w) = M_U (1 - sum_l Y_l w_l / (w_l + i w)); relaxed modulus
// M_R = M_U (1 - sum_l Y_l). Closed-form relaxation and creep for the tests and the lab.
#include <complex>
#include <string>
#include <vector>

namespace viscera::tissue {

struct StandardLinearSolids {
  double unrelaxed_modulus_pa = 0.0;
  std::vector<double> omega_rad_s;  ///< relaxation frequencies w_l
  std::vector<double> weight;  ///< Y_l (dimensionless, sum < 1)

  std::size_t size() const { return omega_rad_s.size(); }
  std::complex<double> complex_modulus(double omega_rad_s) const;
  double q(double omega_rad_s) const;  ///< Re M / Im M
  double relaxed_modulus() const;
  /// Stress after a unit strain step: M_U (1 - sum Y_l (1 - exp(-w_l t))).
  double relaxation_modulus(double t_s) const;
  /// Strain after a unit stress step, by partial fractions over the real poles of 1 / M(s).
  double creep_compliance(double t_s) const;
};

/// Exact one-step update of a memory variable for a strain that varies linearly over the step:
/// zeta(t + dt) = e zeta(t) + a eps(t) + c (eps(t + dt) - eps(t)), with e = exp(-w dt),
/// a = 1 - e, c = 1 - a / (w dt) (series for small w dt). Unconditionally stable.
struct MemoryStep {
  double e, a, c;
  static MemoryStep make(double omega_rad_s, double dt_s);
};

}  // namespace viscera::tissue
