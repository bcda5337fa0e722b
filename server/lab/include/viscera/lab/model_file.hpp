#pragma once  // SPDX-License-Identifier: Apache-2.0
// model.json: a fitted lab model, readable by `viscera-lab predict`.
#include <string>

#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

void write_model(const std::string& path, const MaterialModel& m, const std::string& dataset);
/// Throws common::InputError naming the file and field.
MaterialModel read_model(const std::string& path);

}  // namespace viscera::lab
