#include "viscera/lab/material_export.hpp"

#include <nlohmann/json.hpp>

#include "viscera/lab/specimen_simulation.hpp"

namespace viscera::lab {

std::string material_file_text(const MaterialModel& m, const Dataset& d, const std::string& name, std::string* why) {
  if (!specimen_supports(m, d.mode, why)) return {};
  const GpsLaw law = gps_law(m, d);
  const bool shear = d.mode == Mode::simple_shear;
  const double nu = kSpecimenPoissonRatio;
  nlohmann::ordered_json j;
  j["name"] = name;
  j["density_kg_m3"] = d.specimen.density_kg_m3;
  j["elasticity"] = {{"type", "isotropic"},
                     {"youngs_modulus_pa", shear ? 2 * law.unrelaxed_modulus_pa * (1 + nu) : law.unrelaxed_modulus_pa},
                     {"poisson_ratio", nu}};
  const tissue::GpsMechanisms& g = law.mechanisms;
  nlohmann::ordered_json v{{"model", "relaxation_spectrum"}};
  std::vector<double> times;
  for (double w : g.viscous.omega_rad_s) times.push_back(1.0 / w);
  v["relaxation_times_s"] = times;
  v["relaxation_weights"] = g.viscous.shear_weight;
  v["kelvin_voigt_time_s"] = g.viscous.kelvin_voigt_time_s;
  if (g.energy_map()) {
    v["qlv_stiffening"] = g.stiffening.b;
    v["qlv_form"] = "energy";
    v["qlv_shape"] = g.stiffening.shape == tissue::StiffeningShape::odd_exponential  ? "odd_exponential"
                     : g.stiffening.shape == tissue::StiffeningShape::odd_polynomial ? "odd_polynomial"
                                                                                     : "exponential";
    v["compression_ratio"] = g.asymmetry.compression_ratio;
  }
  if (g.softening.active()) v["softening_d"] = g.softening.d;
  j["viscoelasticity"] = v;
  return j.dump(2) + "\n";
}

}  // namespace viscera::lab
