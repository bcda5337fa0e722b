#include "model_file.hpp"

#include <fstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"

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
  const auto number = [&](const char* key) {
    if (!j.contains(key) || !j[key].is_number()) throw tissue::InputError(path, 0, key, "missing or not a number");
    return j[key].get<double>();
  };
  MaterialModel m;
  if (!j.contains("mechanisms") || !j["mechanisms"].is_array()) throw tissue::InputError(path, 0, "mechanisms", "missing");
  for (const auto& s : j["mechanisms"]) {
    Mechanism k;
    if (!s.is_string() || !parse_mechanism(s.get<std::string>(), &k))
      throw tissue::InputError(path, 0, "mechanisms", s.dump() + " is not a known mechanism");
    m.mechanisms |= 1u << static_cast<unsigned>(k);
  }
  m.modulus_pa = number("modulus_pa");
  m.viscosity_pa_s = number("viscosity_pa_s");
  if (m.has(Mechanism::broadband_relaxation)) {
    m.relaxation_time_s = j.at("relaxation_time_s").get<std::vector<double>>();
    m.relaxation_modulus_pa = j.at("relaxation_modulus_pa").get<std::vector<double>>();
    if (m.relaxation_time_s.size() != m.relaxation_modulus_pa.size())
      throw tissue::InputError(path, 0, "relaxation_modulus_pa", "one modulus per relaxation time expected");
  }
  if (m.has(Mechanism::strain_stiffening)) m.stiffening_b = number("stiffening_b");
  if (m.has(Mechanism::tension_compression_asymmetry)) m.compression_ratio = number("compression_ratio");
  if (m.has(Mechanism::first_load_softening)) m.softening_d = number("softening_d");
  return m;
}

}  // namespace viscera::lab
