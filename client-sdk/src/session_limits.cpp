#include "viscera/client/session_limits.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>

#include "viscera/common/plain_name.hpp"

namespace viscera::client {

const std::array<MaterialParameter, 5>& material_parameters() {
  using M = protocol::MaterialChange;
  static const std::array<MaterialParameter, 5> p = {{
      {"youngs-modulus-pa", "E", "Young's modulus [Pa] (isotropic materials)", 1.0, 1e9, &M::youngs_modulus_pa},
      {"poisson-ratio", "NU", "Poisson's ratio (isotropic materials)", 0.0, 0.4999, &M::poisson_ratio},
      {"density-kg-m3", "RHO", "density [kg/m^3]", 1.0, 1e5, &M::density_kg_m3},
      {"shear-q", "Q", "quality factor in shear (constant-Q materials)", 0.5, 1e4, &M::shear_q},
      {"damping-per-s", "A", "mass-proportional damping [1/s]", 0.0, 1e4, &M::damping_per_s},
  }};
  return p;
}

std::optional<std::string> outside_range(const std::string& name, double value, double lo, double hi) {
  if (value >= lo && value <= hi) return std::nullopt;
  std::ostringstream s;
  s << name << ": " << value << " is outside [" << lo << ", " << hi << "]";
  return s.str();
}

bool is_scene_name(const std::string& n) { return common::is_plain_name(n); }

std::string not_a_scene_name(const std::string& n) { return "SCENE '" + n + "' is not a scene name (letters, digits, '.', '_', '-'; no path)"; }

std::string plain_file_name(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string().substr(0, 64);
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
  if (name.empty() || name[0] == '.') name.insert(0, "m");
  return name.substr(0, 64);
}

}  // namespace viscera::client
