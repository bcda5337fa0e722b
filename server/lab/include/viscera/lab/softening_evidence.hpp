#pragma once  // SPDX-License-Identifier: Apache-2.0
// First-load softening's physical evidence: at the same strain, the stress on reloading below the
// previous peak differs from the stress on first loading. A stiffening response
// cannot show it (it depends on the strain only), nor can rate effects the model already carries.
// Residuals of `model` (data - model, sign-corrected) on strain-controlled tests, in ten bins of
// |strain| over 20-100% of the largest, within each test (same rates, same protocol) or across
// the tests of a session; in each bin with both kinds, first loading minus below the peak,
// combined as a z-score against the noise.
#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

struct SofteningEvidence {
  double z = 0.0;
  int bins = 0;
  long virgin = 0, below_peak = 0;
  bool across_tests = false;
};
/// The evidence of `model`'s residuals on `d` (noise_pa: the data's noise), within each test or
/// across the session's tests (each starting from what the tests before it left).
SofteningEvidence softening_evidence(const MaterialModel& model, const Dataset& d, double noise_pa, bool across_tests);

}  // namespace viscera::lab
