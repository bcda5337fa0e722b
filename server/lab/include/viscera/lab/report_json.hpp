#pragma once  // SPDX-License-Identifier: Apache-2.0
// report.json: every figure of an analysis (or of a prediction), as viscera-lab writes it and the
// Python package returns it; and the organ's material files the analysis hands over.
#include <string>

#include <nlohmann/json.hpp>

#include "viscera/lab/analysis.hpp"

namespace viscera::lab {

/// The material files of an analysis (docs/MATERIAL.md): the model it stands by, in the server's
/// GPS as it is, and the linear baseline's, the tissue to compare it with. Empty text: not written,
/// `why` (or `why_baseline`) says why; `note`: what the hand-over changed.
struct MaterialFiles {
  std::string material, baseline, why, why_baseline, note;
};
MaterialFiles material_files(const Analysis& a, const Dataset& d);

/// report.json of `analyze`; `seconds`: how long it took; "material_file" says what `files` hold
/// (material.json, material-baseline.json).
nlohmann::json report_json(const Analysis& a, const Dataset& d, double seconds, const MaterialFiles& files);

/// report.json of `predict`: per-test RMS errors of a model on a data set.
nlohmann::json prediction_json(const MaterialModel& m, const std::string& model_path, const Dataset& d);

}  // namespace viscera::lab
