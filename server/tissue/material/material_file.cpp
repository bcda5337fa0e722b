#include "viscera/tissue/material/material_file.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/tissue/material/elasticity.hpp"

namespace viscera::tissue {

using common::JsonObject;
using common::parse_json;
using common::read_text_file;
using common::short_number;

namespace {
// Ranges wide enough for any tissue and any material a study may want (bone is about 2e10 Pa),
// finite so that nothing derived from them overflows.
constexpr double kModulusMinPa = 1e-3, kModulusMaxPa = 1e12;
}  // namespace

Material parse_material(const std::string& text, const std::string& source) {
  const nlohmann::json j = parse_json(text, source);
  const JsonObject top(j, source);
  top.require_known({"name", "density_kg_m3", "elasticity", "viscoelasticity"});
  Material m;
  m.name = top.text("name", source);
  m.density_kg_m3 = top.number("density_kg_m3", 1.0, 1e5);
  const JsonObject e = top.object("elasticity");
  const std::string type = e.choice("type", {"isotropic", "transversely_isotropic"}, "");
  if (type == "isotropic") {
    e.require_known({"type", "youngs_modulus_pa", "poisson_ratio"});
    m.isotropic = IsotropicElasticity{e.number("youngs_modulus_pa", kModulusMinPa, kModulusMaxPa), e.number("poisson_ratio", -0.9999, 0.4999)};
    m.elasticity = elasticity_matrix(*m.isotropic, source);
  } else {
    e.require_known({"type", "plane_youngs_modulus_pa", "plane_poisson_ratio", "fibre_youngs_modulus_pa", "fibre_plane_poisson_ratio",
                     "fibre_shear_modulus_pa", "fibre_direction"});
    TransverselyIsotropicElasticity t;
    t.plane_youngs_modulus_pa = e.number("plane_youngs_modulus_pa", kModulusMinPa, kModulusMaxPa);
    t.plane_poisson_ratio = e.number("plane_poisson_ratio", -0.9999, 0.9999);
    t.fibre_youngs_modulus_pa = e.number("fibre_youngs_modulus_pa", kModulusMinPa, kModulusMaxPa);
    t.fibre_plane_poisson_ratio = e.number("fibre_plane_poisson_ratio", -10, 10);
    t.fibre_shear_modulus_pa = e.number("fibre_shear_modulus_pa", kModulusMinPa, kModulusMaxPa);
    const auto d = e.numbers("fibre_direction", 3, -1e3, 1e3);
    t.fibre_direction = Vec3(d[0], d[1], d[2]);
    m.elasticity = elasticity_matrix(t, source);
  }
  if (top.has("viscoelasticity")) {
    const JsonObject v = top.object("viscoelasticity");
    v.require_known({"model", "shear_q", "bulk_q", "band_hz", "mechanisms", "reference_frequency_hz", "qlv_stiffening", "qlv_form",
                     "compression_ratio", "qlv_shape", "relaxation_times_s", "relaxation_weights", "kelvin_voigt_time_s", "softening_d"});
    ViscoelasticSpec spec;
    const std::string model = v.choice("model", {"constant_q", "kelvin_voigt", "relaxation_spectrum"}, "constant_q");
    if (model == "kelvin_voigt") spec.model = ViscoelasticSpec::Model::kelvin_voigt;
    if (model == "relaxation_spectrum") {
      spec.model = ViscoelasticSpec::Model::relaxation_spectrum;
      const std::size_t n = v.has("relaxation_times_s") ? v.value()["relaxation_times_s"].size() : 0;
      if (n > 0) {
        spec.relaxation_times_s = v.numbers("relaxation_times_s", n, 1e-9, 1e9);
        spec.relaxation_weights = v.numbers("relaxation_weights", n, 0, 1);
      }
      spec.kelvin_voigt_time_s = v.number("kelvin_voigt_time_s", 0, 1e6, 0.0);
      spec.softening_d = v.number("softening_d", 0, 0.99, 0.0);
      for (const char* field : {"shear_q", "bulk_q", "band_hz", "mechanisms", "reference_frequency_hz"})
        if (v.has(field)) v.fail(field, "belongs to \"model\": \"constant_q\" or \"kelvin_voigt\" (a spectrum states its times and weights)");
    } else {
      for (const char* field : {"relaxation_times_s", "relaxation_weights", "kelvin_voigt_time_s", "softening_d"})
        if (v.has(field)) v.fail(field, "belongs to \"model\": \"relaxation_spectrum\"");
      spec.shear_q = v.number("shear_q", 0.5, 1e4);
    }
    if (v.has("bulk_q") && !v.value()["bulk_q"].is_null()) spec.bulk_q = v.number("bulk_q", 0.5, 1e4);
    if (v.has("band_hz")) {
      const auto b = v.numbers("band_hz", 2, 1e-9, 1e9);
      if (!(b[1] > b[0])) v.fail("band_hz", "[" + short_number(b[0]) + ", " + short_number(b[1]) + "] must satisfy low < high");
      spec.band_low_hz = b[0];
      spec.band_high_hz = b[1];
    }
    spec.mechanisms = static_cast<int>(v.integer("mechanisms", 1, 8, spec.mechanisms));
    spec.reference_frequency_hz = v.number("reference_frequency_hz", 1e-9, 1e9, spec.reference_frequency_hz);
    spec.qlv_stiffening = v.number("qlv_stiffening", 0, 1e3, spec.qlv_stiffening);
    if (v.choice("qlv_form", {"edge_map", "energy"}, "edge_map") == "energy") spec.qlv_form = GpsStiffening::Form::energy;
    spec.compression_ratio = v.number("compression_ratio", 1e-3, 1e3, spec.compression_ratio);
    if (spec.compression_ratio != 1.0 && spec.qlv_form != GpsStiffening::Form::energy)
      v.fail("compression_ratio", short_number(spec.compression_ratio) + " needs \"qlv_form\": \"energy\"");
    const std::string shape = v.choice("qlv_shape", {"exponential", "odd_exponential", "odd_polynomial"}, "exponential");
    if (shape == "odd_exponential") spec.qlv_shape = StiffeningShape::odd_exponential;
    if (shape == "odd_polynomial") spec.qlv_shape = StiffeningShape::odd_polynomial;
    if (spec.qlv_shape != StiffeningShape::exponential && spec.qlv_form != GpsStiffening::Form::energy)
      v.fail("qlv_shape", shape + " needs \"qlv_form\": \"energy\"");
    m.viscoelasticity = spec;
  }
  return m;
}

Material read_material_file(const std::string& path) { return parse_material(read_text_file(path, std::size_t{1} << 20), path); }

}  // namespace viscera::tissue
