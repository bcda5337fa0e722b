#pragma once  // SPDX-License-Identifier: Apache-2.0
// Kjartansson's (1979) exact constant-Q model (docs/MODEL.md section 3): complex modulus
// M(w) = M0 (i w / w0)^(2 gamma), gamma = arctan(1/Q) / pi, so that tan(delta) = 1/Q at every
// frequency. M0 = |M| at the reference frequency w0.
#include <complex>

namespace viscera::tissue {

struct ConstantQ {
  double q = 0.0;  ///< quality factor (> 0)
  double modulus_pa = 0.0;  ///< |M| at the reference frequency [Pa]
  double reference_frequency_hz = 1.0;  ///< [Hz]

  double gamma() const;
  std::complex<double> complex_modulus(double omega_rad_s) const;
  /// Stress after a unit step of strain at t = 0 [Pa]: M0 (w0 t)^(-2 gamma) / Gamma(1 - 2 gamma).
  double relaxation_modulus(double t_s) const;
  /// Strain after a unit step of stress at t = 0 [1/Pa]: (w0 t)^(2 gamma) / (M0 Gamma(1 + 2 gamma)).
  double creep_compliance(double t_s) const;
};

}  // namespace viscera::tissue
