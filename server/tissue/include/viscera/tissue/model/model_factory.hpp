#pragma once  // SPDX-License-Identifier: Apache-2.0
// Builds a force model by name, the names used by tools, scenes and benchmarks.
#include <memory>
#include <string>
#include <vector>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

/// "gps" (paper form), "gps_energy" (energy-consistent), "gps_large_strain" (energy-consistent
/// with the neo-Hookean backbone, GpsOptions::large_strain; it takes no volume term and ignores
/// volume_fraction), "corotational", "linear".
/// `material_of_tet`: each element's index into `materials` (empty: all the first).
/// volume_fraction > 0 adds the signed-volume term to the GPS variants; the mechanisms (memory
/// variables, Kelvin-Voigt, stiffening, asymmetry, softening) need a GPS variant (InputError otherwise).
std::unique_ptr<ForceModel> make_force_model(const std::string& name, std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials,
                                             double volume_fraction = 0.0, const GpsMechanisms& mechanisms = {},
                                             std::vector<std::uint16_t> material_of_tet = {});

/// The accepted names, for --help texts and error messages.
const std::vector<std::string>& force_model_names();

}  // namespace viscera::tissue
