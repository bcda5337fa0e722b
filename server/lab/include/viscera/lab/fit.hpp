#pragma once
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
/// Each test weighs equally (rows scaled by 1/sqrt(rows)). Stress-controlled tests enter through
/// the stress predicted from their measured strain.
MaterialModel fit_model(const MaterialModel& structure, const std::vector<const TestData*>& tests);

/// RMS of measured minus predicted stress over one test [Pa].
double rms_error_pa(const MaterialModel& m, const TestData& t);

}  // namespace viscera::lab
