#include "viscera/tissue/model/model_factory.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"

namespace viscera::tissue {

using common::InputError;

const std::vector<std::string>& force_model_names() {
  static const std::vector<std::string> names{"gps", "gps_energy", "gps_large_strain", "corotational", "linear"};
  return names;
}

std::unique_ptr<ForceModel> make_force_model(const std::string& name, std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials,
                                             double volume_fraction, const GpsMechanisms& mechanisms, std::vector<std::uint16_t> material_of_tet) {
  if (name == "gps" || name == "gps_energy") {
    const GpsVariant v = name == "gps" ? GpsVariant::paper : GpsVariant::energy_consistent;
    return std::make_unique<GpsModel>(std::move(mesh), std::move(materials), std::move(material_of_tet), GpsOptions{v, volume_fraction, mechanisms});
  }
  if (name == "gps_large_strain") {
    // The backbone holds the volume: no volume term (volume_fraction is the other variants').
    GpsOptions o{GpsVariant::energy_consistent, 0.0, mechanisms};
    o.large_strain = true;
    try {
      return std::make_unique<GpsModel>(std::move(mesh), std::move(materials), std::move(material_of_tet), o);
    } catch (const std::invalid_argument& e) {
      throw InputError("model", 0, "name", "'gps_large_strain': " + std::string(e.what()));
    }
  }
  if (mechanisms.has_memory() || mechanisms.stiffening.active() || mechanisms.asymmetry.active())
    throw InputError("model", 0, "name", "'" + name + "': viscoelasticity needs a GPS model (gps, gps_energy or gps_large_strain)");
  if (name == "corotational")
    return std::make_unique<FiniteElementModel>(std::move(mesh), FeKind::corotational, std::move(materials), std::move(material_of_tet));
  if (name == "linear")
    return std::make_unique<FiniteElementModel>(std::move(mesh), FeKind::linear, std::move(materials), std::move(material_of_tet));
  throw InputError("model", 0, "name", "'" + name + "' is not one of gps, gps_energy, gps_large_strain, corotational, linear");
}

}  // namespace viscera::tissue
