#include "model_file.hpp"

#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "common/known_fields.hpp"

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
  if (m.has(Mechanism::strain_stiffening)) j["stiffening_b"] = m.stiffening_b;
  if (m.has(Mechanism::tension_compression_asymmetry)) j["compression_ratio"] = m.compression_ratio;
  if (m.has(Mechanism::first_load_softening)) j["softening_d"] = m.softening_d;
  std::ofstream out(path);
  out << j.dump(2) << "\n";
  if (!out) throw tissue::InputError(path, 0, "", "cannot write");
}

MaterialModel read_model(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw tissue::InputError(path, 0, "", "cannot open file");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw tissue::InputError(path, 0, "JSON", e.what());
  }
  if (!j.is_object()) throw tissue::InputError(path, 0, "", "not a JSON object (a model.json written by viscera-lab analyze)");
  tissue::require_known_fields(j, path, "",
                               {"model", "fitted_to", "units", "mechanisms", "modulus_pa", "viscosity_pa_s", "relaxation_time_s",
                                "relaxation_modulus_pa", "stiffening_b", "compression_ratio", "softening_d"});
  // A value in [lo, hi] (the open ends excluded where said): what the fit can produce.
  const auto check = [&](const std::string& field, const json& v, double lo, bool lo_open, double hi, bool hi_open) {
    if (!v.is_number()) throw tissue::InputError(path, 0, field, v.dump() + " is not a number");
    const double x = v.get<double>();
    if (!(lo_open ? x > lo : x >= lo) || !(hi_open ? x < hi : x <= hi)) {
      std::ostringstream range;
      range << x << " is outside " << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
      throw tissue::InputError(path, 0, field, range.str());
    }
    return x;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const auto number = [&](const char* key, double lo, bool lo_open, double hi, bool hi_open) {
    if (!j.contains(key)) throw tissue::InputError(path, 0, key, "missing");
    return check(key, j[key], lo, lo_open, hi, hi_open);
  };
  const auto numbers = [&](const char* key, bool positive) {
    if (!j.contains(key) || !j[key].is_array()) throw tissue::InputError(path, 0, key, "missing or not an array");
    std::vector<double> out;
    for (std::size_t k = 0; k < j[key].size(); ++k) out.push_back(check(std::string(key) + "[" + std::to_string(k) + "]", j[key][k], 0.0, positive, inf, true));
    return out;
  };
  MaterialModel m;
  if (!j.contains("mechanisms") || !j["mechanisms"].is_array()) throw tissue::InputError(path, 0, "mechanisms", "missing or not an array");
  for (const auto& s : j["mechanisms"]) {
    Mechanism k;
    if (!s.is_string() || !parse_mechanism(s.get<std::string>(), &k))
      throw tissue::InputError(path, 0, "mechanisms", s.dump() + " is not a known mechanism");
    m.mechanisms |= 1u << static_cast<unsigned>(k);
  }
  m.modulus_pa = number("modulus_pa", 0.0, false, inf, true);
  m.viscosity_pa_s = number("viscosity_pa_s", 0.0, false, inf, true);
  if (m.has(Mechanism::broadband_relaxation)) {
    m.relaxation_time_s = numbers("relaxation_time_s", true);
    m.relaxation_modulus_pa = numbers("relaxation_modulus_pa", false);
    if (m.relaxation_time_s.size() != m.relaxation_modulus_pa.size())
      throw tissue::InputError(path, 0, "relaxation_modulus_pa", "one modulus per relaxation time expected");
  }
  if (m.has(Mechanism::strain_stiffening)) m.stiffening_b = number("stiffening_b", 0.0, false, inf, true);
  if (m.has(Mechanism::tension_compression_asymmetry)) m.compression_ratio = number("compression_ratio", 0.0, true, inf, true);
  if (m.has(Mechanism::first_load_softening)) m.softening_d = number("softening_d", 0.0, false, 1.0, true);
  return m;
}

}  // namespace viscera::lab
