#pragma once  // SPDX-License-Identifier: Apache-2.0
// Data sets shaped like a tissue lab's, generated outside the lab's own code (issue 23): ramp-holds
// at three rates (one ramp 0.05 s) and one in compression, triangular cycles of growing amplitude
// through tension and compression, a creep-recovery test under stress control with 0.05 s stress
// ramps, non-uniform sampling dense after every change of the command (never on the change
// itself), uniaxial or simple shear, specimens of several sizes, noise 0.5-2% of the peak of the
// measured quantity, a noise column in two data sets of three. The tests are one session on one
// specimen, 60 s apart and unloaded between them: what a test leaves (first loading's peaks, a
// permanent set, a slipped grip) is where the next one starts (dataset.json "history": "carried").
//
// The truths are written here, not taken from the lab's forms: linear damping on the strain rate,
//     sigma = f(eps, history) + eta d eps/dt + hereditary relaxation on the strain,
// with f one of the elastic laws below (several outside the lab's candidate forms). Under strain
// control the stress is evaluated in closed form at the sample times from the piecewise-linear
// command; under stress control the strain is integrated by backward Euler at 1/1000 of the
// sampling interval (checked against 1/4000).
#include <string>
#include <vector>

#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"

namespace viscera::lab::test {

enum class LabTruth {
  none,  // linear Kelvin-Voigt
  exponential_stiffening,  // f = E/B (exp(B eps) - 1); odd in shear: sign(g) E/B (exp(B |g|) - 1)
  polynomial_stiffening,  // f = E eps (1 + B^2 eps^2 / 6), symmetric (outside the lab's forms)
  asymmetry,  // f = E eps in tension, r E eps in compression
  softening,  // below the largest |eps| seen (m) on its side: f = E eps (1 - d (1 - |eps|/m))
  recovering_softening,  // the same, m recovering towards |eps| with time constant T at rest (outside)
  broadband,  // two relaxation times off the lab's decade grid
  power_law,  // E_p (1 + t/tau0)^-alpha relaxation (outside; no creep test: nonlocal in time)
  broadband_and_stiffening,  // two effects at once
  // Outside the lab's catalogue of causes (issue 36): what real tissue and real instruments add.
  permanent_set,  // plastic flow: f = E (eps - p), p moving so that |eps - p| <= the yield strain (set left at zero stress)
  instrument_drift,  // the load cell's zero drifts linearly over the session (tests in a row, 60 s apart)
  rate_thinning,  // viscous stress a power of the strain rate, |rate|^n with n 0.2-0.5, besides the linear damping
  grip_slip,  // the specimen slips in its grips once the stress first passes a threshold: a part of the strain is lost
};
const char* name(LabTruth t);
/// What the lab should name for this truth (mechanism names, strongest expected first; empty: none).
std::vector<std::string> expected_causes(LabTruth t);
/// Whether `causes` (the lab's verdict) are exactly the ones expected for the truth, in any order.
bool names_expected_causes(LabTruth t, const std::vector<Mechanism>& causes);
/// Whether the truth lies outside the lab's candidate forms.
bool out_of_family(LabTruth t);
/// Whether the truth holds an effect outside the lab's catalogue of causes altogether (no mechanism
/// of the lab's describes it): the adequacy verdict must say the model does not explain the data.
bool out_of_catalogue(LabTruth t);

struct LabDatasetTruth {
  LabTruth truth = LabTruth::none;
  double size = 1.0;  ///< effect size relative to today's (1, 0.3, 0.1)
  double modulus_pa = 0, viscosity_pa_s = 0;
  double stiffening_b = 0, compression_ratio = 1, softening_d = 0, recovery_s = 0;
  double spectrum_pa[2] = {0, 0}, spectrum_tau_s[2] = {1, 1};
  double power_pa = 0, power_alpha = 0, power_tau0_s = 1;
  double yield_strain = 0;  ///< permanent_set
  double drift_pa_per_s = 0;  ///< instrument_drift: the load cell's zero, per second of the session
  double thinning_pa = 0, thinning_n = 1, thinning_rate = 1;  ///< rate_thinning: thinning_pa (|rate| / thinning_rate)^n [Pa, -, 1/s]
  double slip_stress_pa = 0, slip_fraction = 0;  ///< grip_slip: at the first |stress| above slip_stress_pa, this fraction of the strain is lost
  double stress_noise_pa = 0;  ///< SD of the stress noise of the strain-controlled tests
  double strain_noise = 0;  ///< SD of the strain noise of the stress-controlled test
  double creep_stress_noise_pa = 0;  ///< SD of the load cell's noise in the creep test
  bool noise_column = true;
  Mode mode = Mode::uniaxial;
};

/// Writes the data set of `truth` at `size` for `seed` into `folder` and returns every number.
LabDatasetTruth write_lab_dataset(unsigned seed, LabTruth truth, double size, const std::string& folder);

/// Linear Kelvin-Voigt (E 1-100 kPa, eta/E 5-50 ms): write_lab_dataset(seed, none, 1, folder).
LabDatasetTruth write_kelvin_voigt_lab_dataset(unsigned seed, const std::string& folder);

}  // namespace viscera::lab::test
