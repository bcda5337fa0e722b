#include "viscera/lab/model_file.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <fstream>

#include <nlohmann/json.hpp>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"

namespace viscera::lab {

using nlohmann::json;

void write_model(const std::string& path, const MaterialModel& m, const std::string& dataset) {
  json j;
  j["model"] = m.describe();
  j["fitted_to"] = dataset;
  j["units"] = "SI: Pa, Pa s, s; strain dimensionless";
  j["mechanisms"] = json::array();
  for (Mechanism k : kMechanisms)
    if (m.has(k)) j["mechanisms"].push_back(name(k));
  j["modulus_pa"] = m.modulus_pa;
  j["viscosity_pa_s"] = m.viscosity_pa_s;
  if (m.has(Mechanism::broadband_relaxation)) {
    j["relaxation_time_s"] = m.relaxation_time_s;
    j["relaxation_modulus_pa"] = m.relaxation_modulus_pa;
  }
  if (m.has(Mechanism::strain_stiffening)) {
    j["stiffening_form"] = name(m.stiffening_form);
    j["stiffening_b"] = m.stiffening_b;
  }
  if (m.has(Mechanism::tension_compression_asymmetry)) j["compression_ratio"] = m.compression_ratio;
  if (m.has(Mechanism::first_load_softening)) {
    j["softening_d"] = m.softening_d;
    j["softening_kept"] = m.softening_kept;
  }
  if (m.has(Mechanism::contact_take_up)) j["contact_strain"] = m.contact_strain;
  common::write_file_text(path, j.dump(2) + "\n");
}

MaterialModel read_model(const std::string& path) {
  const json j = common::read_json_file(path);
  if (!j.is_object()) throw common::InputError(path, 0, "", "not a JSON object (a model.json written by viscera-lab analyze)");
  const common::JsonObject top(j, path);
  top.require_known({"model", "fitted_to", "units", "mechanisms", "modulus_pa", "viscosity_pa_s", "relaxation_time_s", "relaxation_modulus_pa",
                     "stiffening_form", "stiffening_b", "compression_ratio", "softening_d", "softening_kept", "contact_strain"});
  // Each value in the range a fit can produce (finite; open ends checked where they matter).
  const double big = 1e300;
  const auto numbers = [&](const char* key, bool positive) {
    const json& a = top.array(key);
    std::vector<double> v = top.numbers(key, a.size(), 0.0, big);
    for (std::size_t k = 0; k < v.size(); ++k)
      if (positive && !(v[k] > 0)) top.fail(std::string(key) + "[" + std::to_string(k) + "]", "0 is outside (0, inf)");
    return v;
  };
  MaterialModel m;
  for (const auto& s : top.array("mechanisms")) {
    Mechanism k;
    if (!s.is_string() || !parse_mechanism(s.get<std::string>(), &k)) top.fail("mechanisms", common::show_json(s) + " is not a known mechanism");
    m.mechanisms |= 1u << static_cast<unsigned>(k);
  }
  m.modulus_pa = top.number("modulus_pa", 0.0, big);
  m.viscosity_pa_s = top.number("viscosity_pa_s", 0.0, big);
  if (m.has(Mechanism::broadband_relaxation)) {
    m.relaxation_time_s = numbers("relaxation_time_s", true);
    m.relaxation_modulus_pa = numbers("relaxation_modulus_pa", false);
    if (m.relaxation_time_s.size() != m.relaxation_modulus_pa.size()) top.fail("relaxation_modulus_pa", "one modulus per relaxation time expected");
  }
  if (m.has(Mechanism::strain_stiffening)) {
    m.stiffening_b = top.number("stiffening_b", 0.0, big);
    // Files from before the forms existed are Fung's exponential.
    const std::string form = top.choice("stiffening_form", {"exponential", "odd_exponential", "odd_polynomial", "ogden"}, "exponential");
    parse_stiffening_form(form, &m.stiffening_form);
  }
  if (m.has(Mechanism::tension_compression_asymmetry)) {
    m.compression_ratio = top.number("compression_ratio", 0.0, big);
    if (!(m.compression_ratio > 0)) top.fail("compression_ratio", "0 is outside (0, inf)");
  }
  if (m.has(Mechanism::first_load_softening)) {
    m.softening_d = top.number("softening_d", 0.0, 1.0);
    if (!(m.softening_d < 1)) top.fail("softening_d", "1 is outside [0, 1)");
    m.softening_kept = top.number("softening_kept", 0.0, 1.0, 1.0);  // files from before it: nothing recovers
  }
  if (m.has(Mechanism::contact_take_up)) m.contact_strain = top.number("contact_strain", 0.0, 1.0);
  return m;
}

}  // namespace viscera::lab
