#include "viscera/lab/material_export.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cstdio>
#include <numbers>

#include <nlohmann/json.hpp>

#include "viscera/lab/specimen_simulation.hpp"

namespace viscera::lab {

std::string material_file_text(const MaterialModel& m, const Dataset& d, const std::string& name, std::string* why, std::string* note) {
  if (!specimen_supports(m, d.mode, why)) return {};
  const GpsLaw law = gps_law(m, d);
  const tissue::GpsMechanisms& g = law.mechanisms;
  std::vector<double> times, weights = g.viscous.shear_weight;
  for (double w : g.viscous.omega_rad_s) times.push_back(1.0 / w);
  // The dashpot as a stiff, short Maxwell branch: the unrelaxed modulus grows by it, the other
  // weights shrink in proportion, the relaxed modulus stays.
  double unrelaxed = law.unrelaxed_modulus_pa, dashpot_time = g.viscous.kelvin_voigt_time_s;
  if (dashpot_time > 0 && times.size() < tissue::GpsViscous::kMaxMechanisms) {
    const double k = kDashpotBranchStiffness;
    for (double& w : weights) w /= 1 + k;
    times.push_back(dashpot_time / k);
    weights.push_back(k / (1 + k));
    unrelaxed *= 1 + k;
    if (note) {
      char b[300];
      std::snprintf(b, sizeof b,
                    "the Kelvin-Voigt dashpot (time %.4g s) as a Maxwell branch of %.0fx the unrelaxed modulus and time %.4g s: the same viscosity "
                    "below about %.3g Hz, a bounded stiffness above",
                    dashpot_time, k, dashpot_time / k, k / (2 * std::numbers::pi * dashpot_time));
      *note = b;
    }
    dashpot_time = 0;
  }
  const bool shear = d.mode == Mode::simple_shear;
  const double nu = kSpecimenPoissonRatio;
  nlohmann::ordered_json j;
  j["name"] = name;
  j["density_kg_m3"] = d.specimen.density_kg_m3;
  j["elasticity"] = {{"type", "isotropic"}, {"youngs_modulus_pa", shear ? 2 * unrelaxed * (1 + nu) : unrelaxed}, {"poisson_ratio", nu}};
  nlohmann::ordered_json v{{"model", "relaxation_spectrum"}};
  v["relaxation_times_s"] = times;
  v["relaxation_weights"] = weights;
  v["kelvin_voigt_time_s"] = dashpot_time;
  if (g.energy_map()) {
    v["qlv_stiffening"] = g.stiffening.b;
    v["qlv_form"] = "energy";
    v["qlv_shape"] = g.stiffening.shape == tissue::StiffeningShape::odd_exponential  ? "odd_exponential"
                     : g.stiffening.shape == tissue::StiffeningShape::odd_polynomial ? "odd_polynomial"
                                                                                     : "exponential";
    v["compression_ratio"] = g.asymmetry.compression_ratio;
  }
  if (g.softening.active()) v["softening_d"] = g.softening.d;
  if (m.has(Mechanism::contact_take_up) && note) {
    char b[200];
    std::snprintf(b, sizeof b, "%sthe platens' gap (contact taken up over the first %.3g%% of compression) belongs to the test: left out",
                  note->empty() ? "" : "; ", 100 * m.contact_strain);
    *note += b;
  }
  j["viscoelasticity"] = v;
  return j.dump(2) + "\n";
}

}  // namespace viscera::lab
