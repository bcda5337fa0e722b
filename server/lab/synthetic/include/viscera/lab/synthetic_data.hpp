#pragma once  // SPDX-License-Identifier: Apache-2.0
// Synthetic data sets with one hidden effect (or none), chosen by a seed, for testing viscera-lab.
// The truth is computed on a different code path from the lab's: closed-form hereditary integrals
// of piecewise-linear strain histories (strain control), and a finely integrated ODE (stress
// control, RK4 at 1/200 of the sampling interval). The lab only ever sees the written folder.
#include <string>

#include "viscera/lab/dataset.hpp"

namespace viscera::lab::test {

enum class Effect { none, broadband_relaxation, strain_stiffening, tension_compression_asymmetry, first_load_softening };
const char* effect_name(Effect e);

struct Truth {
  Effect effect = Effect::none;
  double modulus_pa = 0, tau_s = 0;  // Kelvin-Voigt baseline: sigma = E (s + tau ds/dt)
  double spectrum_pa[2] = {0, 0}, spectrum_tau_s[2] = {1, 1};  // broadband: two off-grid relaxations
  double stiffening_b = 0, compression_ratio = 1, softening_d = 0;
  // Broadband, outside the lab's family: a continuous power-law relaxation E_p (1 + t/tau0)^-alpha
  // instead of the two exponentials (no finite set of memory variables is exact for it).
  double power_pa = 0, power_alpha = 0, power_tau0_s = 1;
  double noise_pa = 0;
  bool odd = false;  // simple shear: the elastic shape is odd in the strain
};

/// Writes the data set for `seed` into `folder` and returns its truth (for messages only).
Truth write_synthetic_dataset(unsigned seed, const std::string& folder);
/// The same protocols with broadband relaxation from a continuous power-law spectrum (every seed).
Truth write_power_law_dataset(unsigned seed, const std::string& folder);

}  // namespace viscera::lab::test
