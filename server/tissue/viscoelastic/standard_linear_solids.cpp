#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::tissue {

std::complex<double> StandardLinearSolids::complex_modulus(double w) const {
  std::complex<double> m = 1.0;
  for (std::size_t l = 0; l < size(); ++l) m -= weight[l] * omega_rad_s[l] / std::complex<double>(omega_rad_s[l], w);
  return unrelaxed_modulus_pa * m;
}

double StandardLinearSolids::q(double w) const {
  const auto m = complex_modulus(w);
  return m.real() / m.imag();
}

double StandardLinearSolids::relaxed_modulus() const {
  double s = 1.0;
  for (double y : weight) s -= y;
  return unrelaxed_modulus_pa * s;
}

double StandardLinearSolids::relaxation_modulus(double t) const {
  double s = 1.0;
  for (std::size_t l = 0; l < size(); ++l) s -= weight[l] * (1.0 - std::exp(-omega_rad_s[l] * t));
  return unrelaxed_modulus_pa * s;
}

double StandardLinearSolids::creep_compliance(double t) const {
  // 1/(s M(s)) = D(s) / (M_U s N(s)), D(s) = prod (s + w_l), N(s) = D(s) M(s) / M_U. The zeros of
  // N are real and interlace the -w_l (M(s)/M_U is increasing on each interval), so bisection
  // finds them; residues give J(t) = 1/M_R + sum_k D(p_k) / (M_U p_k N'(p_k)) exp(p_k t).
  const std::size_t L = size();
  if (L == 0) return 1.0 / unrelaxed_modulus_pa;
  const auto m_over_mu = [&](double s) {
    double v = 1.0;
    for (std::size_t l = 0; l < L; ++l) v -= weight[l] * omega_rad_s[l] / (omega_rad_s[l] + s);
    return v;
  };
  std::vector<double> w = omega_rad_s;
  std::sort(w.begin(), w.end());
  double J = 1.0 / relaxed_modulus();
  for (std::size_t k = 0; k < L; ++k) {
    // Zero of M(s) in (-w_k, -w_{k-1}) (or (-w_0, 0) for k = 0): M/M_U goes from -inf to
    // its value at the right end, which is positive there.
    double lo = -w[k], hi = k == 0 ? 0.0 : -w[k - 1];
    const double span = hi - lo;
    lo += 1e-15 * span;
    hi -= 1e-15 * span;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (m_over_mu(mid) < 0 ? lo : hi) = mid;
    }
    const double p = 0.5 * (lo + hi);
    // N(s) = D(s) m(s) => at a zero of m, N'(p) = D(p) m'(p); residue = 1 / (M_U p m'(p)).
    double dm = 0.0;
    for (std::size_t l = 0; l < L; ++l) dm += weight[l] * omega_rad_s[l] / ((omega_rad_s[l] + p) * (omega_rad_s[l] + p));
    J += std::exp(p * t) / (unrelaxed_modulus_pa * p * dm);
  }
  return J;
}

MemoryStep MemoryStep::make(double w, double dt) {
  const double x = w * dt;
  const double a = -std::expm1(-x);
  // c = 1 - a/x = (x + expm1(-x)) / x; the series avoids the cancellation for small x.
  const double c = x < 1e-4 ? x / 2 - x * x / 6 + x * x * x / 24 : (x - a) / x;
  return {1.0 - a, a, c};
}

}  // namespace viscera::tissue
