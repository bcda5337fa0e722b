#pragma once  // SPDX-License-Identifier: Apache-2.0
// Fitting the lab's material models: non-negative least squares for the linear parameters
// (Lawson-Hanson), a log-grid search refined by golden sections for each nonlinear parameter
// (variable projection), and leave-one-test-out prediction for held-out errors.
#include <vector>

#include <Eigen/Core>

#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

/// min |A x - b| subject to x >= 0 (Lawson & Hanson 1974).
Eigen::VectorXd nonnegative_least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

/// Fits `structure` (mechanisms and relaxation times set; parameters ignored) to the tests.
/// Each test weighs equally (rows scaled by 1/sqrt(rows)). Strain-controlled tests are fitted on
/// their stress; stress-controlled tests on their strain, simulated under the measured stress
/// (stress_controlled.hpp), in equivalent stress (strain error x apparent modulus). The nonlinear
/// parameters are searched on the strain-controlled tests; a last Gauss-Newton refinement of the
/// moduli and viscosities takes every test.
/// Rows of one test the fit must not see (held out for cross-validation within tests); the
/// model still runs through them, driven by the measured history.
struct HeldOutRows {
  const TestData* test = nullptr;
  std::size_t begin = 0, end = 0;
};
MaterialModel fit_model(const MaterialModel& structure, const std::vector<const TestData*>& tests, const HeldOutRows& held = {});

/// RMS error of one test in what it measured: stress [Pa] under strain control, strain under
/// stress control.
double rms_error_measured(const MaterialModel& m, const TestData& t);

/// The same in pascals: strain errors times the test's apparent modulus under stress control.
double rms_error_pa(const MaterialModel& m, const TestData& t);

}  // namespace viscera::lab
