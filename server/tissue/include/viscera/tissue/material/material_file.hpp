#pragma once  // SPDX-License-Identifier: Apache-2.0
// Material files (JSON), documented in docs/MATERIAL.md:
//   { "density_kg_m3": 1060,
//     "elasticity": { "type": "isotropic", "youngs_modulus_pa": 5000, "poisson_ratio": 0.45 } }
// or "type": "transversely_isotropic" with plane_youngs_modulus_pa, plane_poisson_ratio,
// fibre_youngs_modulus_pa, fibre_plane_poisson_ratio, fibre_shear_modulus_pa, fibre_direction [x,y,z].
// Optional "viscoelasticity": { "model": "constant_q" | "kelvin_voigt", "shear_q": 4.8,
//   "bulk_q": 20 (absent: no bulk relaxation), "band_hz": [0.01, 10], "mechanisms": 3,
//   "reference_frequency_hz": 2, "qlv_stiffening": 0, "qlv_form": "edge_map" | "energy",
//   "compression_ratio": 1 } -- the elastic constants are then the moduli at the reference frequency.
#include <optional>
#include <string>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

namespace viscera::tissue {

struct Material {
  std::string name;
  double density_kg_m3 = 0.0;
  Mat6 elasticity = Mat6::Zero();  ///< at the reference frequency when viscoelastic
  std::optional<IsotropicElasticity> isotropic;  ///< its constants, when the material is isotropic
  std::optional<ViscoelasticSpec> viscoelasticity;
};

/// Reads and checks a material file; InputError names the file and the field.
Material read_material_file(const std::string& path);
/// Parses material JSON text (source names it in errors).
Material parse_material(const std::string& json_text, const std::string& source);

}  // namespace viscera::tissue
