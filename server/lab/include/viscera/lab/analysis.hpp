#pragma once  // SPDX-License-Identifier: Apache-2.0
// viscera-lab's method (docs/MODEL.md section 4): fit the baseline, show where it is wrong (per test,
// on held-out tests), name the cause from candidate mechanisms whose held-out gain is clearly
// above the noise of the data, extend the model, refit and measure the gain on held-out tests.
#include <functional>
#include <string>
#include <vector>

#include "viscera/lab/adequacy.hpp"
#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/parameter_uncertainty.hpp"

namespace viscera::lab {

struct TestFigures {
  std::string file;
  double fit_rms_pa = 0.0;  ///< model fitted to all tests
  double heldout_rms_pa = 0.0;  ///< model fitted to the other tests (leave one test out)
  double noise_pa = 0.0;
  /// Stress-controlled tests: the same in the measured quantity, strain (the _pa figures are these
  /// times the test's apparent modulus, an equivalent stress so that tests compare).
  double fit_rms_strain = 0.0, heldout_rms_strain = 0.0, noise_strain = 0.0;
};

struct ModelEvaluation {
  MaterialModel model;  ///< fitted to all tests
  std::vector<TestFigures> tests;
  double fit_rms_pa = 0.0, heldout_rms_pa = 0.0;  ///< root mean square over tests
};

struct Candidate {
  Mechanism mechanism;
  int round = 0;  ///< 1: tried on the baseline; 2..: on the extended model
  double heldout_before_pa = 0.0, heldout_after_pa = 0.0;
  bool accepted = false;
  std::string evidence;  ///< the residual signature that points at it
};

/// A model run on the tetrahedral specimen (viscera's GPS, implicit, inertia) next to its
/// material-point law.
struct SpecimenCheck {
  std::string model;
  bool ran = false;
  std::string note;
  std::vector<std::string> files;
  std::vector<double> specimen_rms_pa, law_rms_pa;
  long steps = 0, newton_iterations = 0;
};

struct AnalyzeOptions {
  bool specimen = true;  ///< also simulate baseline and final on the tetrahedral specimen
  /// Tests with more rows are decimated for the fit (decimation.hpp); the report says so.
  std::size_t max_fit_points = 2000;
  /// Also run the whole selection once per test without it (nested leave-one-out): the honest gain.
  bool nested = true;
  /// Draws of the bootstrap over tests for the parameters' uncertainties (0: none).
  int bootstrap_replicates = 40;
};

/// One fold of the nested leave-one-out: the mechanisms chosen without the test, and the error of
/// that model (fitted without the test) on it.
struct NestedFold {
  std::string file;
  std::vector<Mechanism> causes;
  double heldout_rms_pa = 0.0;
};

/// Whether the mechanisms chosen on all tests are named as found (report.json "causes_status").
enum class CausesStatus {
  none,  ///< nothing chosen: the baseline explains the data
  confirmed,  ///< the nested leave-one-out's honest gain holds by the rule that accepts a mechanism
  not_confirmed,  ///< it ran and its gain does not hold: nothing is named as found; the baseline stands
  tentative,  ///< it did not run (fewer than three tests, or turned off): named, as tentative
};
const char* to_string(CausesStatus s);

/// The rule that accepts a mechanism, for a held-out RMS `after` [Pa] against `before` [Pa]: the
/// mean square error falls by more than half the noise variance and the RMS by at least 5%.
bool gain_holds(double before_pa, double after_pa, double noise_pa);

struct Analysis {
  std::string dataset;
  double noise_pa = 0.0;  ///< the first estimate (noise_level_pa, RMS over tests): every ratio to the noise uses it
  NoiseCheck noise_check;
  ModelEvaluation baseline, final;
  std::vector<Candidate> candidates;
  std::vector<Mechanism> causes;  ///< accepted, strongest first
  /// Baseline held-out RMS / final held-out RMS. The mechanisms were chosen on all tests (each
  /// candidate judged by its held-out error), so every test had a say in the choice: optimistic.
  double gain = 1.0;
  /// Nested leave-one-out (AnalyzeOptions::nested, three tests or more): for each test the
  /// selection ran without it; the held-out RMS over tests that played no part in choosing, and the
  /// baseline's held-out RMS over it. 0 when not run.
  std::vector<NestedFold> nested;
  double nested_heldout_rms_pa = 0.0, nested_gain = 0.0;
  /// Why the nested leave-one-out did not run ("" when it ran).
  std::string nested_not_run;
  /// What `causes` are worth: confirmed by the honest gain, tentative without it, or not confirmed
  /// (then the report names none as found, and the baseline is the model written).
  CausesStatus causes_status = CausesStatus::none;
  /// The model the analysis stands by: `final`'s, or the baseline's when the choice did not hold.
  const MaterialModel& supported_model() const { return causes_status == CausesStatus::not_confirmed ? baseline.model : final.model; }
  /// The causes named as found or tentative: `causes`, or none when they were not confirmed.
  std::vector<Mechanism> named_causes() const { return causes_status == CausesStatus::not_confirmed ? std::vector<Mechanism>{} : causes; }
  /// Whether the model the analysis stands by explains the data, and what its residual looks like.
  Adequacy adequacy;
  /// The standard errors and intervals of that model's parameters.
  ParameterUncertainty uncertainty;
  std::string verdict;  ///< one paragraph: what is wrong, why, what still does not fit
  std::vector<std::string> decimated;  ///< "file: N rows, fitted on M" for the tests decimated for the fit
  std::vector<SpecimenCheck> specimen;  ///< baseline and final on the specimen
};

/// Fits `structure` to all tests and, for every held-out unit, to the rest (held-out prediction).
/// What a held-out error holds out: a whole test (the model fitted to the other tests predicts
/// it), or one of four consecutive blocks of a test's rows (fitted to every other row, the test's
/// own other blocks included; for an effect that only one test's history shows, such as
/// reloading below a previous peak).
enum class HeldOut { tests, blocks };
ModelEvaluation evaluate(const MaterialModel& structure, const Dataset& d, HeldOut unit = HeldOut::tests);

/// The whole analysis; `progress` receives one line per stage, with an estimate of the time the
/// rest will take once the baseline's fits have been timed.
Analysis analyze(const Dataset& d, const std::function<void(const std::string&)>& progress = {}, const AnalyzeOptions& options = {});

}  // namespace viscera::lab
