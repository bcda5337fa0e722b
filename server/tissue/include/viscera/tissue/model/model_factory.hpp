#pragma once
// Builds a force model by name, the names used by tools, scenes and benchmarks.
#include <memory>
#include <string>
#include <vector>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

/// "gps" (paper form), "gps_energy" (energy-consistent), "corotational", "linear".
/// volume_fraction > 0 adds the signed-volume term to the GPS variants; the mechanisms (memory
/// variables, Kelvin-Voigt, stiffening, asymmetry, softening) need a GPS variant (InputError otherwise).
std::unique_ptr<ForceModel> make_force_model(const std::string& name, std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials,
                                             double volume_fraction = 0.0, const GpsMechanisms& mechanisms = {});

/// The accepted names, for --help texts and error messages.
const std::vector<std::string>& force_model_names();

}  // namespace viscera::tissue
