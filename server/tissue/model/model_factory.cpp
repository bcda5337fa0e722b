#include "viscera/tissue/model/model_factory.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"

namespace viscera::tissue {

using common::InputError;

const std::vector<std::string>& force_model_names() {
  static const std::vector<std::string> names{"gps", "gps_energy", "corotational", "linear"};
  return names;
}

std::unique_ptr<ForceModel> make_force_model(const std::string& name, std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials,
                                             double volume_fraction, const GpsMechanisms& mechanisms, std::vector<std::uint16_t> material_of_tet) {
  if (name == "gps" || name == "gps_energy") {
    const GpsVariant v = name == "gps" ? GpsVariant::paper : GpsVariant::energy_consistent;
    return std::make_unique<GpsModel>(std::move(mesh), std::move(materials), std::move(material_of_tet), GpsOptions{v, volume_fraction, mechanisms});
  }
  if (mechanisms.has_memory() || mechanisms.stiffening.active() || mechanisms.asymmetry.active())
    throw InputError("model", 0, "name", "'" + name + "': viscoelasticity needs a GPS model (gps or gps_energy)");
  if (name == "corotational")
    return std::make_unique<FiniteElementModel>(std::move(mesh), FeKind::corotational, std::move(materials), std::move(material_of_tet));
  if (name == "linear")
    return std::make_unique<FiniteElementModel>(std::move(mesh), FeKind::linear, std::move(materials), std::move(material_of_tet));
  throw InputError("model", 0, "name", "'" + name + "' is not one of gps, gps_energy, corotational, linear");
}

}  // namespace viscera::tissue
