#include "scene_file.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "common/known_fields.hpp"

namespace viscera::runtime {

using nlohmann::json;
using tissue::InputError;
using tissue::require_known_fields;

SceneSpec read_scene_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open file");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw InputError(path, 0, "JSON", e.what());
  }
  const auto dir = std::filesystem::path(path).parent_path();
  const auto number = [&](const json& o, const char* key, const std::string& prefix, double lo, double hi, double fallback) {
    if (!o.contains(key)) return fallback;
    if (!o[key].is_number()) throw InputError(path, 0, prefix + key, o[key].dump() + " is not a number");
    const double v = o[key].get<double>();
    if (!(v >= lo && v <= hi))
      throw InputError(path, 0, prefix + key, o[key].dump() + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  };
  if (!j.is_object()) throw InputError(path, 0, "JSON", "the scene must be an object");
  require_known_fields(j, path, "", {"name", "domain_id", "physics_rate_hz", "mesh_rate_hz", "max_tool_speed_m_s", "organ", "instruments"});
  SceneSpec s;
  s.source = path;
  s.name = j.value("name", std::filesystem::path(path).stem().string());
  s.domain_id = static_cast<std::uint32_t>(number(j, "domain_id", "", 0, 230, 0));
  s.physics_rate_hz = number(j, "physics_rate_hz", "", 10, 10000, 1000);
  s.mesh_rate_hz = number(j, "mesh_rate_hz", "", 0, 240, 60);
  if (!j.contains("organ") || !j["organ"].is_object()) throw InputError(path, 0, "organ", "missing or not an object");
  const json& o = j["organ"];
  require_known_fields(o, path, "organ.", {"mesh", "material", "model", "scale_m_per_unit", "refine", "stable_step", "added_mass_fraction",
                           "physics_threads", "volume_term", "damping_per_s", "gravity_m_s2", "contact_stiffness_n_per_m",
                           "contact_damping_s_per_m", "grasp_stiffness_n_per_m", "fix_slab"});
  for (const char* key : {"mesh", "material"})
    if (!o.contains(key) || !o[key].is_string()) throw InputError(path, 0, std::string("organ.") + key, "missing (a path)");
  s.mesh = (dir / o["mesh"].get<std::string>()).string();
  s.material = (dir / o["material"].get<std::string>()).string();
  s.model = o.value("model", "gps_energy");
  s.scale_m_per_unit = number(o, "scale_m_per_unit", "organ.", 1e-6, 1e3, 1.0);
  s.damping_per_s = number(o, "damping_per_s", "organ.", 0, 1e4, 0.0);
  s.gravity_m_s2 = number(o, "gravity_m_s2", "organ.", 0, 100, 9.81);
  s.volume_term = number(o, "volume_term", "organ.", 0, 0.99, 0.5);
  s.refine = static_cast<int>(number(o, "refine", "organ.", 0, 2, 0));
  const std::string step = o.value("stable_step", "element");
  if (step != "element" && step != "global")
    throw InputError(path, 0, "organ.stable_step", "'" + step + "' is not element or global");
  s.global_stable_step = step == "global";
  s.added_mass_fraction = number(o, "added_mass_fraction", "organ.", 0, 1, 0.0);
  s.physics_threads = static_cast<int>(number(o, "physics_threads", "organ.", 1, 8, 1));
  if (o.contains("physics_threads") && o["physics_threads"].get<double>() != s.physics_threads)
    throw InputError(path, 0, "organ.physics_threads", o["physics_threads"].dump() + " is not a whole number");
  s.contact_stiffness_n_per_m = number(o, "contact_stiffness_n_per_m", "organ.", 1e-3, 1e7, 200.0);
  s.grasp_stiffness_n_per_m = number(o, "grasp_stiffness_n_per_m", "organ.", 1e-3, 1e7, 100.0);
  s.contact_damping_s_per_m = number(o, "contact_damping_s_per_m", "organ.", 0, 1e4, 0.0);
  s.max_tool_speed_m_s = number(j, "max_tool_speed_m_s", "", 1e-3, 100, 0.5);
  if (o.contains("fix_slab")) {
    const json& f = o["fix_slab"];
    if (!f.is_array() || f.size() != 3 || !f[0].is_string() || !f[1].is_string() || !f[2].is_number())
      throw InputError(path, 0, "organ.fix_slab", "must be [axis, side, fraction], e.g. [\"z\", \"max\", 0.2]");
    s.fix_axis = f[0].get<std::string>();
    s.fix_side = f[1].get<std::string>();
    s.fix_fraction = f[2].get<double>();
    if (s.fix_axis != "x" && s.fix_axis != "y" && s.fix_axis != "z") throw InputError(path, 0, "organ.fix_slab", "axis '" + s.fix_axis + "' is not x, y or z");
    if (s.fix_side != "min" && s.fix_side != "max") throw InputError(path, 0, "organ.fix_slab", "side '" + s.fix_side + "' is not min or max");
    if (!(s.fix_fraction > 0 && s.fix_fraction <= 1)) throw InputError(path, 0, "organ.fix_slab", "fraction must lie in (0, 1]");
  }
  if (!j.contains("instruments") || !j["instruments"].is_array() || j["instruments"].empty())
    throw InputError(path, 0, "instruments", "missing or empty");
  std::set<std::uint32_t> ids;
  for (std::size_t k = 0; k < j["instruments"].size(); ++k) {
    const json& i = j["instruments"][k];
    const std::string prefix = "instruments[" + std::to_string(k) + "].";
    if (!i.is_object()) throw InputError(path, 0, prefix.substr(0, prefix.size() - 1), "not an object");
    require_known_fields(i, path, prefix, {"id", "kind", "tip_radius_m", "grasp_radius_m"});
    InstrumentSpec spec;
    spec.id = static_cast<std::uint32_t>(number(i, "id", prefix, 1, 1e6, 0));
    if (spec.id == 0) throw InputError(path, 0, prefix + "id", "missing");
    if (!ids.insert(spec.id).second) throw InputError(path, 0, prefix + "id", std::to_string(spec.id) + " is used twice");
    spec.kind = i.value("kind", "probe");
    if (spec.kind != "probe" && spec.kind != "grasper")
      throw InputError(path, 0, prefix + "kind", "'" + spec.kind + "' is not probe or grasper");
    spec.grasp_radius_m = number(i, "grasp_radius_m", prefix, 1e-4, 0.05, 0.01);
    spec.tip_radius_m = number(i, "tip_radius_m", prefix, 1e-4, 0.05, 0.005);
    s.instruments.push_back(spec);
  }
  return s;
}

std::vector<std::string> list_scenes(const std::string& directory) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec)) {
    if (entry.path().extension() != ".json") continue;
    try {
      read_scene_file(entry.path().string());
      names.push_back(entry.path().stem().string());
    } catch (const InputError&) {
      // not a scene (or a broken one): not offered
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace viscera::runtime
