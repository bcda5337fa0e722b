#include "material/material_file.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "common/known_fields.hpp"
#include "material/elasticity.hpp"

namespace viscera::tissue {

namespace {
using nlohmann::json;

double number(const json& j, const std::string& key, const std::string& source, const std::string& prefix) {
  const std::string field = prefix + key;
  if (!j.contains(key)) throw InputError(source, 0, field, "missing");
  if (!j.at(key).is_number()) throw InputError(source, 0, field, j.at(key).dump() + " is not a number");
  const double v = j.at(key).get<double>();
  if (!std::isfinite(v)) throw InputError(source, 0, field, "is not finite");
  return v;
}
}  // namespace

Material parse_material(const std::string& text, const std::string& source) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(source, 0, "JSON", e.what());
  }
  if (!j.is_object()) throw InputError(source, 0, "", "expected a JSON object");
  require_known_fields(j, source, "", {"name", "density_kg_m3", "elasticity", "viscoelasticity"});
  Material m;
  m.name = j.value("name", source);
  m.density_kg_m3 = number(j, "density_kg_m3", source, "");
  if (!(m.density_kg_m3 > 0)) throw InputError(source, 0, "density_kg_m3", std::to_string(m.density_kg_m3) + " must be positive");
  if (!j.contains("elasticity") || !j["elasticity"].is_object()) throw InputError(source, 0, "elasticity", "missing or not an object");
  const json& e = j["elasticity"];
  const std::string type = e.value("type", "");
  const std::string where = source;
  if (type == "isotropic") {
    require_known_fields(e, source, "elasticity.", {"type", "youngs_modulus_pa", "poisson_ratio"});
    m.isotropic = IsotropicElasticity{number(e, "youngs_modulus_pa", source, "elasticity."), number(e, "poisson_ratio", source, "elasticity.")};
    m.elasticity = elasticity_matrix(*m.isotropic, where);
  } else if (type == "transversely_isotropic") {
    require_known_fields(e, source, "elasticity.", {"type", "plane_youngs_modulus_pa", "plane_poisson_ratio", "fibre_youngs_modulus_pa",
                                                    "fibre_plane_poisson_ratio", "fibre_shear_modulus_pa", "fibre_direction"});
    TransverselyIsotropicElasticity t;
    t.plane_youngs_modulus_pa = number(e, "plane_youngs_modulus_pa", source, "elasticity.");
    t.plane_poisson_ratio = number(e, "plane_poisson_ratio", source, "elasticity.");
    t.fibre_youngs_modulus_pa = number(e, "fibre_youngs_modulus_pa", source, "elasticity.");
    t.fibre_plane_poisson_ratio = number(e, "fibre_plane_poisson_ratio", source, "elasticity.");
    t.fibre_shear_modulus_pa = number(e, "fibre_shear_modulus_pa", source, "elasticity.");
    if (!e.contains("fibre_direction") || !e["fibre_direction"].is_array() || e["fibre_direction"].size() != 3)
      throw InputError(source, 0, "elasticity.fibre_direction", "must be an array of three numbers");
    for (int k = 0; k < 3; ++k) t.fibre_direction[k] = e["fibre_direction"][static_cast<std::size_t>(k)].get<double>();
    m.elasticity = elasticity_matrix(t, where);
  } else {
    throw InputError(source, 0, "elasticity.type", "'" + type + "' is not isotropic or transversely_isotropic");
  }
  if (j.contains("viscoelasticity")) {
    const json& v = j["viscoelasticity"];
    if (!v.is_object()) throw InputError(source, 0, "viscoelasticity", "must be an object");
    require_known_fields(v, source, "viscoelasticity.", {"model", "shear_q", "bulk_q", "band_hz", "mechanisms", "reference_frequency_hz",
                                                         "qlv_stiffening", "qlv_form", "compression_ratio"});
    ViscoelasticSpec spec;
    const std::string model = v.value("model", "constant_q");
    if (model == "kelvin_voigt") spec.model = ViscoelasticSpec::Model::kelvin_voigt;
    else if (model != "constant_q")
      throw InputError(source, 0, "viscoelasticity.model", "'" + model + "' is not constant_q or kelvin_voigt");
    spec.shear_q = number(v, "shear_q", source, "viscoelasticity.");
    if (!(spec.shear_q > 0)) throw InputError(source, 0, "viscoelasticity.shear_q", v["shear_q"].dump() + " must be positive");
    if (v.contains("bulk_q") && !v["bulk_q"].is_null()) {
      spec.bulk_q = number(v, "bulk_q", source, "viscoelasticity.");
      if (!(*spec.bulk_q > 0)) throw InputError(source, 0, "viscoelasticity.bulk_q", v["bulk_q"].dump() + " must be positive");
    }
    if (v.contains("band_hz")) {
      const json& b = v["band_hz"];
      if (!b.is_array() || b.size() != 2 || !b[0].is_number() || !b[1].is_number())
        throw InputError(source, 0, "viscoelasticity.band_hz", "must be [low, high] in hertz");
      spec.band_low_hz = b[0].get<double>();
      spec.band_high_hz = b[1].get<double>();
      if (!(spec.band_low_hz > 0 && spec.band_high_hz > spec.band_low_hz))
        throw InputError(source, 0, "viscoelasticity.band_hz", b.dump() + " must satisfy 0 < low < high");
    }
    if (v.contains("mechanisms")) {
      if (!v["mechanisms"].is_number_integer() || v["mechanisms"].get<int>() < 1 || v["mechanisms"].get<int>() > 8)
        throw InputError(source, 0, "viscoelasticity.mechanisms", v["mechanisms"].dump() + " must be an integer from 1 to 8");
      spec.mechanisms = v["mechanisms"].get<int>();
    }
    if (v.contains("reference_frequency_hz")) {
      spec.reference_frequency_hz = number(v, "reference_frequency_hz", source, "viscoelasticity.");
      if (!(spec.reference_frequency_hz > 0))
        throw InputError(source, 0, "viscoelasticity.reference_frequency_hz", v["reference_frequency_hz"].dump() + " must be positive");
    }
    if (v.contains("qlv_stiffening")) {
      spec.qlv_stiffening = number(v, "qlv_stiffening", source, "viscoelasticity.");
      if (!(spec.qlv_stiffening >= 0))
        throw InputError(source, 0, "viscoelasticity.qlv_stiffening", v["qlv_stiffening"].dump() + " must be >= 0");
    }
    if (v.contains("qlv_form")) {
      const json& f = v["qlv_form"];
      if (f == "energy") spec.qlv_form = GpsViscoelasticity::QlvForm::energy;
      else if (f != "edge_map")
        throw InputError(source, 0, "viscoelasticity.qlv_form", f.dump() + " is not \"edge_map\" or \"energy\"");
    }
    if (v.contains("compression_ratio")) {
      spec.compression_ratio = number(v, "compression_ratio", source, "viscoelasticity.");
      if (!(spec.compression_ratio > 0))
        throw InputError(source, 0, "viscoelasticity.compression_ratio", v["compression_ratio"].dump() + " must be positive");
      if (spec.compression_ratio != 1.0 && spec.qlv_form != GpsViscoelasticity::QlvForm::energy)
        throw InputError(source, 0, "viscoelasticity.compression_ratio", v["compression_ratio"].dump() + " needs \"qlv_form\": \"energy\"");
    }
    m.viscoelasticity = spec;
  }
  return m;
}

Material read_material_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_material(ss.str(), path);
}

}  // namespace viscera::tissue
