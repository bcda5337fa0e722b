#pragma once  // SPDX-License-Identifier: Apache-2.0
// A measured data set (README "The data a user brings"): a folder with dataset.json and one CSV
// per test (time_s, strain, stress_pa[, stress_sd_pa]). SI units: seconds, engineering strain,
// pascals. Reading checks everything a file can get wrong and names file, line and field.
#include <optional>
#include <string>
#include <vector>

namespace viscera::lab {

enum class Mode { uniaxial, simple_shear };
enum class Control { strain, stress };
/// What a test starts from ("history" in dataset.json). carried (the default): the tests on one
/// specimen were made on it in the listed order, and each starts in the state the ones before left
/// (test_history.hpp); reset: each test starts from an untouched specimen (a fresh one, or one
/// that recovered fully between tests).
enum class History { carried, reset };

struct Specimen {
  double length_m = 0, width_m = 0, thickness_m = 0, density_kg_m3 = 0;
};

struct TestData {
  std::string file;  ///< as named in dataset.json
  Control control = Control::strain;
  /// The test's own specimen (tests[k].specimen in dataset.json: each field given there replaces
  /// the data set's); absent: the data set's. Real data sets hold several specimens of different sizes.
  std::optional<Specimen> specimen;
  std::vector<double> time_s, strain, stress_pa, stress_sd_pa;  ///< sd empty if not given
  /// The largest tension and compression strains (both >= 0) the test's specimen went through in
  /// the tests before it (History::carried; carry_history() sets them, 0 for a first test).
  double before_tension = 0.0, before_compression = 0.0;
};

struct Dataset {
  std::string name, folder;
  std::string import_note;  ///< how `viscera-lab import` made it, with its units ("import" in dataset.json; "" otherwise)
  Mode mode = Mode::uniaxial;
  /// "contact": "platens" in dataset.json: the specimen was compressed between platens it was not
  /// bonded to (they take up contact, and cannot pull); "bonded" (the default): glued or gripped.
  bool platens = false;
  History history = History::carried;
  Specimen specimen;
  std::vector<TestData> tests;
};

/// The specimen a test was measured on: its own, else the data set's.
inline const Specimen& specimen_of(const Dataset& d, const TestData& t) { return t.specimen ? *t.specimen : d.specimen; }

/// Reads DATASET_DIR/dataset.json and its CSVs; throws common::InputError on bad input.
Dataset read_dataset(const std::string& folder);
/// Writes a data set in the same format (used by the synthetic generator).
void write_dataset(const Dataset& d, const std::string& folder);

/// Noise of a sampled quantity from its second differences (the median absolute value, robust
/// to the changes of a command): the SD for white noise; 0 for a command sampled exactly.
double noise_from_second_differences(const std::vector<double>& v);
/// The smallest nonzero change between neighbouring samples (a reading's resolution, if quantised).
double quantum_of(const std::vector<double>& v);
/// The noise of a reading (a measured quantity): noise_from_second_differences, or where more than
/// half of them are exactly zero (a reading quantised more coarsely than its noise) their RMS over
/// the central 98%, never below quantum_of(v) / sqrt(12).
double noise_of_reading(const std::vector<double>& v);

const char* to_string(Mode m);
const char* to_string(Control c);
const char* to_string(History h);

}  // namespace viscera::lab
