#pragma once  // SPDX-License-Identifier: Apache-2.0
// A test's noise, by two independent paths. The first (noise_level_measured) from the second
// differences of every sample; the second the spread of the measured quantity in the holds, about a running
// mean. Second differences see only the noise that changes from one sample to the next: noise
// that a logger's filter has smoothed (correlated over many samples) looks several times smaller
// to them than it is, and every ratio to the noise would be that much too large. The spread in
// the holds sees it whole, as long as the hold's own relaxation is smooth over the window.
#include <cstddef>
#include <string>

#include "viscera/lab/dataset.hpp"

namespace viscera::lab {

/// The first estimate: the noise of what a test measured. Under strain control the stress [Pa]:
/// the RMS of stress_sd_pa if given, else from the second differences of the stress
/// (noise_of_reading); under stress control the strain, the same way.
double noise_level_measured(const TestData& t);
/// The same in pascals (strain noise times the apparent modulus under stress control).
double noise_level_pa(const TestData& t);

/// The two estimates agree when neither is more than this factor above the other.
inline constexpr double kNoiseAgreementFactor = 2.0;

struct HoldNoise {
  double sd = 0.0;  ///< of the measured quantity (stress [Pa], or strain under stress control); 0 without holds
  std::size_t samples = 0;  ///< residuals it rests on
  int holds = 0;  ///< holds used
  double window_s = 0.0;  ///< the running mean's width in the first hold used [s]
};

/// The measured quantity in the holds of `t` (its command, the strain or under stress control the
/// stress, held within its own noise for at least three windows), less its running mean over
/// `window_s` in that hold's own sampling (at least 9 samples: a logger may thin its rate in long
/// holds), after the first window of each hold (where the relaxation
/// bends fastest): the robust SD (median absolute value / 0.6745), corrected for the mean's own
/// share of the noise.
HoldNoise noise_in_holds(const TestData& t, double window_s = 1.0);

/// The two estimates over a data set's tests that have holds.
struct NoiseCheck {
  int tests = 0, holds = 0;  ///< tests with holds, and holds used
  double window_s = 0.0;  ///< the running mean's width in the first test with holds [s]
  double first_pa = 0.0;  ///< the first estimate over the same tests (RMS) [Pa]
  bool first_stated = false;  ///< the first estimate is the data's own stress_sd_pa (in some of those tests)
  double holds_pa = 0.0;  ///< the spread in their holds (RMS over tests) [Pa]
  bool agree = true;  ///< within kNoiseAgreementFactor of each other (true without holds)
};
NoiseCheck check_noise(const Dataset& d);

}  // namespace viscera::lab
