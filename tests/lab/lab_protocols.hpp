#pragma once
// Data sets shaped like a tissue lab's, generated outside the lab's own code (issue 23): ramp-holds
// at three rates (one ramp 0.05 s) and one in compression, triangular cycles of growing amplitude
// through tension and compression, a creep-recovery test under stress control with 0.05 s stress
// ramps, non-uniform sampling dense after every change of the command (never on the change
// itself), uniaxial or simple shear, noise 0.5-2% of the peak of the measured quantity.
// The truth here is linear Kelvin-Voigt, sigma = E eps + eta d eps/dt, computed in closed form:
// stress from the exact strain rate of the piecewise-linear command, and under stress control the
// strain from the exact solution of eta eps' + E eps = sigma(t) over each linear piece of sigma.
#include <string>

#include "viscera/lab/dataset.hpp"

namespace viscera::lab::test {

struct KelvinVoigtTruth {
  double modulus_pa = 0, viscosity_pa_s = 0;
  double stress_noise_pa = 0;  ///< SD of the stress noise of the strain-controlled tests
  double strain_noise = 0;  ///< SD of the strain noise of the stress-controlled test
  double creep_stress_noise_pa = 0;  ///< SD of the load cell's noise in the creep test
};

/// Writes a data set whose truth is a random Kelvin-Voigt solid (E 1-100 kPa, eta/E 5-50 ms) into
/// `folder`; the seed picks every number.
KelvinVoigtTruth write_kelvin_voigt_lab_dataset(unsigned seed, const std::string& folder);

}  // namespace viscera::lab::test
