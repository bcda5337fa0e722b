#pragma once  // SPDX-License-Identifier: Apache-2.0
// Whether a fitted model explains the data: its residual (data - model, the model fitted to all
// tests) judged against the data's noise, test by test, and what the residual looks like where it
// does not. Real tissue and real instruments hold effects outside the lab's four causes (permanent
// set after a large stretch, a load cell that drifts, viscosity that is not linear in the rate, a
// specimen that slips in its grips); the lab then names whichever of its causes helps most, and
// only this judgement says that the model still misses the data.
//
// The rule: the model explains the data when the residual's RMS over tests is at most
// kAdequacyFactor times the noise's, and no strain-controlled test's residual is more than
// kAdequacyTestFactor times its own noise. The catalogue's own forms do not fit every truth of
// their kind exactly (an additive relaxation fitted by memory on the elastic shape, one stiffening
// form fitted by another): on 54 data sets whose truths lie in the catalogue the ratio reached 1.6,
// and the per-test ratio of strain-controlled tests 2.1. A stress-controlled test's residual, a
// strain error times the apparent modulus, amplifies a small misfit of the elastic law: it is
// described, not judged on its own.
#include <string>
#include <vector>

#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

inline constexpr double kAdequacyFactor = 2.0;
inline constexpr double kAdequacyTestFactor = 3.0;

/// One test's residual against its noise.
struct TestAdequacy {
  std::string file;
  double residual_to_noise = 0.0;  ///< RMS residual / noise (equivalent stress under stress control)
  double mean_to_noise = 0.0;  ///< the residual's mean / noise: an offset of the whole test
  double session_start_s = 0.0;  ///< when the test began in the session (the tests in the order listed, back to back)
  bool judged = true;  ///< counted by the per-test rule (strain-controlled)
};

/// The residual in one phase of the tests' commands.
struct PhaseResidual {
  std::string phase;  ///< loading (moving away from zero), unloading (towards it), hold, reversal
  double rms_to_noise = 0.0;  ///< RMS of residual / noise over the phase's samples
  std::size_t samples = 0;
};

struct Adequacy {
  bool explained = true;
  double residual_to_noise = 0.0;  ///< RMS residual over tests / RMS noise over tests
  std::vector<TestAdequacy> tests;
  std::vector<PhaseResidual> phases;
  /// Correlations (Pearson) of the squared normalised residual with the strain amplitude
  /// (|strain| / the test's largest) and with log |strain rate| (moving samples only), and of the
  /// signed normalised residual with the time since the session began (a drifting instrument).
  double correlation_amplitude = 0.0, correlation_rate = 0.0, correlation_session_time = 0.0;
  /// The mean residual / noise where the command is back near zero (within 5% of the test's
  /// largest) after it went past half of its largest: a set that remains (0 when no test returns).
  double set_at_zero_to_noise = 0.0;
  std::size_t set_samples = 0;
  std::vector<std::string> findings;  ///< what stands out in the residual, one sentence each
};

/// Judges `m` (fitted to all of `d`'s tests) on `d`. `noise_pa` per test as noise_level_pa.
Adequacy judge_adequacy(const MaterialModel& m, const Dataset& d);

}  // namespace viscera::lab
