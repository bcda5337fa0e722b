#pragma once  // SPDX-License-Identifier: Apache-2.0
// Writes OUT_DIR/report.json, report.md (with SVG plots per test) and model.json.
#include <string>

#include "viscera/lab/analysis.hpp"

namespace viscera::lab {

void write_report(const Analysis& a, const Dataset& d, const std::string& out_dir, double seconds);

/// For `predict`: per-test RMS of a given model on a data set.
void write_prediction(const MaterialModel& m, const std::string& model_path, const Dataset& d, const std::string& out_dir);

}  // namespace viscera::lab
