#pragma once  // SPDX-License-Identifier: Apache-2.0
// Stress-controlled tests (creep, creep-recovery) simulated as what they are: the measured stress
// history imposed on the model and the strain computed, so that a model is judged on the quantity
// the test measured. The law (material_model.hpp) in terms of its elastic shape s,
//     eta s' = sigma - E s - sum_l E_l h_l,    h_l' = s' - h_l / tau_l,
// is linear in x = (s, h_1..h_L) with the stress as input: x' = A x + g sigma(t). A is similar to
// a symmetric matrix (a diagonal minus a rank-one term, scaled by the square roots of the moduli),
// so its modes are real and decay; each mode is integrated exactly over every interval between
// samples with the stress linear on each piece of its command path (command_path.hpp). The strain is then the elastic shape inverted, sample by
// sample with the history (first-load softening).
#include <vector>

#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

/// Strain under the test's measured stress, the specimen at rest where the command path starts.
std::vector<double> predict_strain(const MaterialModel& m, const TestData& t);

/// Largest |stress| over largest |strain| of a test [Pa]: turns the strain errors of a
/// stress-controlled test into an equivalent stress, so that tests of both controls compare.
double apparent_modulus_pa(const TestData& t);

/// What the test measured, predicted: stress under strain control, strain under stress control.
std::vector<double> predict_measured(const MaterialModel& m, const TestData& t);

}  // namespace viscera::lab
