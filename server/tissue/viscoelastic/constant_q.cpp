#include "viscera/tissue/viscoelastic/constant_q.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>

namespace viscera::tissue {

double ConstantQ::gamma() const { return std::atan(1.0 / q) / M_PI; }

std::complex<double> ConstantQ::complex_modulus(double omega) const {
  const double w0 = 2 * M_PI * reference_frequency_hz;
  // (i w / w0)^(2g) = |w/w0|^(2g) exp(i pi g sign(w)).
  const double g = gamma();
  const double mag = std::pow(std::abs(omega) / w0, 2 * g);
  const double phase = M_PI * g * (omega >= 0 ? 1.0 : -1.0);
  return modulus_pa * mag * std::complex<double>(std::cos(phase), std::sin(phase));
}

double ConstantQ::relaxation_modulus(double t) const {
  const double w0 = 2 * M_PI * reference_frequency_hz, g = gamma();
  return modulus_pa * std::pow(w0 * t, -2 * g) / std::tgamma(1 - 2 * g);
}

double ConstantQ::creep_compliance(double t) const {
  const double w0 = 2 * M_PI * reference_frequency_hz, g = gamma();
  return std::pow(w0 * t, 2 * g) / (modulus_pa * std::tgamma(1 + 2 * g));
}

}  // namespace viscera::tissue
