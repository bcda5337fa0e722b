#include "viscera/runtime/scene_file.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"

namespace viscera::runtime {

using common::JsonObject;

using common::InputError;
using common::JsonObject;
using nlohmann::json;

namespace {

std::array<double, 3> point(const JsonObject& o, const char* key) {
  const auto v = o.numbers(key, 3, -1e3, 1e3);
  return {v[0], v[1], v[2]};
}

/// The name or tag of an element set (a physical group of the mesh) at `key`, as text.
std::string element_set(const JsonObject& o, const char* key) {
  const json& set = o.value()[key];
  if (set.is_string() && !set.get<std::string>().empty() && set.get<std::string>().size() <= 128) return set.get<std::string>();
  if (set.is_number_integer() && set.get<long long>() > 0 && set.get<long long>() <= 2'147'483'647) return std::to_string(set.get<long long>());
  o.fail(key, "'" + common::printable(set.dump()) + "' is neither the name (1-128 characters) nor the positive tag of a physical group of the mesh");
}

RegionSpec read_region(const JsonObject& r, const std::filesystem::path& dir, std::set<std::string>& names) {
  r.require_known({"name", "material", "sphere", "box", "elements"});
  RegionSpec region;
  region.name = r.text("name");
  if (region.name.empty() || region.name.size() > 64) r.fail("name", "must have 1 to 64 characters");
  if (!names.insert(region.name).second) r.fail("name", "'" + common::printable(region.name) + "' is used twice");
  region.material = (dir / r.text("material")).string();
  if (int(r.has("sphere")) + int(r.has("box")) + int(r.has("elements")) != 1)
    r.fail("sphere", "a region is one of a \"sphere\", a \"box\" or \"elements\" (a tagged element set of the mesh)");
  if (r.has("elements")) {
    region.shape = RegionSpec::Shape::elements;
    region.element_set = element_set(r, "elements");
    return region;
  }
  if (r.has("box")) {
    const JsonObject b = r.object("box");
    b.require_known({"lo_m", "hi_m"});
    region.shape = RegionSpec::Shape::box;
    region.lo_m = point(b, "lo_m");
    region.hi_m = point(b, "hi_m");
    for (int a = 0; a < 3; ++a)
      if (!(region.lo_m[a] < region.hi_m[a])) b.fail("hi_m", "must exceed lo_m on every axis");
    return region;
  }
  const JsonObject sphere = r.object("sphere");
  sphere.require_known({"center_m", "radius_m", "random_center"});
  region.radius_m = sphere.number("radius_m", 1e-4, 10);
  if (sphere.has("center_m") == sphere.has("random_center")) sphere.fail("center_m", "a sphere has either a \"center_m\" or a \"random_center\"");
  if (sphere.has("center_m")) {
    region.center_m = point(sphere, "center_m");
    return region;
  }
  const JsonObject random = sphere.object("random_center");
  random.require_known({"seed", "depth_m", "facing"});
  region.random_center = true;
  region.seed = static_cast<std::uint64_t>(random.integer("seed", 0, 9'007'199'254'740'991LL));  // JSON's exact integers
  const auto depth = random.numbers("depth_m", 2, 0, 1);
  if (!(depth[0] <= depth[1])) random.fail("depth_m", "must be [least, most] with least <= most");
  region.min_depth_m = depth[0];
  region.max_depth_m = depth[1];
  if (random.has("facing")) {
    region.facing = point(random, "facing");
    const double n = std::sqrt(region.facing[0] * region.facing[0] + region.facing[1] * region.facing[1] + region.facing[2] * region.facing[2]);
    if (!(n > 0)) random.fail("facing", "must be a direction (not zero)");
    for (double& c : region.facing) c /= n;
  }
  return region;
}

}  // namespace

SceneSpec read_scene_file(const std::string& path) {
  const json j = common::read_json_file(path);
  const JsonObject top(j, path);
  const auto dir = std::filesystem::path(path).parent_path();
  top.require_known({"name", "domain_id", "physics_rate_hz", "mesh_rate_hz", "max_tool_speed_m_s", "organ", "instruments"});
  SceneSpec s;
  s.source = path;
  s.name = top.text("name", std::filesystem::path(path).stem().string());
  s.domain_id = static_cast<std::uint32_t>(top.integer("domain_id", 0, 230, 0));
  // Whole hertz: the tick grid's period is 1/rate, and a rate such as 333.3 Hz would say more
  // precision than the clock's slots keep.
  s.physics_rate_hz = static_cast<double>(top.integer("physics_rate_hz", 10, 10000, 1000));
  s.mesh_rate_hz = top.number("mesh_rate_hz", 0, 240, 60);
  s.max_tool_speed_m_s = top.number("max_tool_speed_m_s", 1e-3, 100, 0.5);
  const JsonObject o = top.object("organ");
  o.require_known({"mesh",
                   "material",
                   "model",
                   "scale_m_per_unit",
                   "refine",
                   "stable_step",
                   "added_mass_fraction",
                   "physics_threads",
                   "volume_term",
                   "damping_per_s",
                   "gravity_m_s2",
                   "contact_stiffness_n_per_m",
                   "contact_damping_s_per_m",
                   "contact",
                   "contact_friction_static",
                   "contact_friction_kinetic",
                   "contact_force_limit_n",
                   "grasp_stiffness_n_per_m",
                   "fix_slab",
                   "fix_elements",
                   "regions",
                   "strain_radius_m",
                   "largest_edge_strain"});
  s.mesh = (dir / o.text("mesh")).string();
  s.material = (dir / o.text("material")).string();
  s.model = o.choice("model", {"gps", "gps_energy", "gps_large_strain", "corotational", "linear"}, "gps_energy");
  s.scale_m_per_unit = o.number("scale_m_per_unit", 1e-6, 1e3, 1.0);
  s.damping_per_s = o.number("damping_per_s", 0, 1e4, 0.0);
  s.gravity_m_s2 = o.number("gravity_m_s2", 0, 100, 9.81);
  s.volume_term = o.number("volume_term", 0, 0.99, 0.5);
  s.refine = static_cast<int>(o.integer("refine", 0, 2, 0));
  s.global_stable_step = o.choice("stable_step", {"element", "global"}, "element") == "global";
  s.added_mass_fraction = o.number("added_mass_fraction", 0, 1, 0.0);
  s.physics_threads = static_cast<int>(o.integer("physics_threads", 1, 8, 1));
  s.contact_stiffness_n_per_m = o.number("contact_stiffness_n_per_m", 1e-3, 1e7, 200.0);
  s.grasp_stiffness_n_per_m = o.number("grasp_stiffness_n_per_m", 1e-3, 1e7, 100.0);
  s.contact_damping_s_per_m = o.number("contact_damping_s_per_m", 0, 1e4, 0.0);
  s.contact_proxy = o.choice("contact", {"penalty", "proxy"}, "penalty") == "proxy";
  s.contact_friction_static = o.number("contact_friction_static", 0, 2, 0.15);
  s.contact_friction_kinetic = o.number("contact_friction_kinetic", 0, 2, std::min(0.1, s.contact_friction_static));
  if (s.contact_friction_kinetic > s.contact_friction_static)
    o.fail("contact_friction_kinetic", std::to_string(s.contact_friction_kinetic) + " is above contact_friction_static " +
                                           std::to_string(s.contact_friction_static) + ": sliding never holds more than sticking");
  s.contact_force_limit_n = o.number("contact_force_limit_n", 0.1, 1000, 15.0);
  s.strain_radius_m = o.number("strain_radius_m", 0.001, 0.05, 0.02);
  s.largest_edge_strain = o.number("largest_edge_strain", 0.01, 1.5, 0.4);
  if (o.has("fix_slab") && o.has("fix_elements"))
    o.fail("fix_elements", "the organ is held either by a slab (fix_slab) or by an element set (fix_elements), not both");
  if (o.has("fix_elements")) s.fix_elements = element_set(o, "fix_elements");
  if (o.has("fix_slab")) {
    const json& f = o.array("fix_slab");
    if (f.size() != 3 || !f[0].is_string() || !f[1].is_string() || !f[2].is_number())
      o.fail("fix_slab", "must be [axis, side, fraction], e.g. [\"z\", \"max\", 0.2]");
    s.fix_axis = f[0].get<std::string>();
    s.fix_side = f[1].get<std::string>();
    s.fix_fraction = f[2].get<double>();
    if (s.fix_axis != "x" && s.fix_axis != "y" && s.fix_axis != "z")
      o.fail("fix_slab", "axis '" + common::printable(s.fix_axis) + "' is not x, y or z");
    if (s.fix_side != "min" && s.fix_side != "max") o.fail("fix_slab", "side '" + common::printable(s.fix_side) + "' is not min or max");
    if (!(s.fix_fraction > 0 && s.fix_fraction <= 1)) o.fail("fix_slab", "fraction must lie in (0, 1]");
  }
  if (o.has("regions")) {
    const json& regions = o.array("regions");
    std::set<std::string> names;
    for (std::size_t k = 0; k < regions.size(); ++k)
      s.regions.push_back(read_region(JsonObject(regions[k], path, "organ.regions[" + std::to_string(k) + "]"), dir, names));
  }
  const json& instruments = top.array("instruments", 1);
  std::set<std::uint32_t> ids;
  for (std::size_t k = 0; k < instruments.size(); ++k) {
    const JsonObject i(instruments[k], path, "instruments[" + std::to_string(k) + "]");
    i.require_known({"id", "kind", "tip_radius_m", "grasp_radius_m", "blade_length_m", "cut_force_n"});
    InstrumentSpec spec;
    spec.id = static_cast<std::uint32_t>(i.integer("id", 1, 1'000'000));
    if (!ids.insert(spec.id).second) i.fail("id", std::to_string(spec.id) + " is used twice");
    const std::string kind = i.choice("kind", {"probe", "grasper", "scalpel"}, "probe");
    spec.kind = kind == "grasper" ? InstrumentKind::grasper : kind == "scalpel" ? InstrumentKind::scalpel : InstrumentKind::probe;
    if (spec.kind != InstrumentKind::scalpel)
      for (const char* key : {"blade_length_m", "cut_force_n"})
        if (i.has(key)) i.fail(key, "is for a scalpel; this is a " + kind);
    spec.grasp_radius_m = i.number("grasp_radius_m", 1e-4, 0.05, 0.01);
    spec.tip_radius_m = i.number("tip_radius_m", 1e-4, 0.05, spec.kind == InstrumentKind::scalpel ? 0.001 : 0.005);
    spec.blade_length_m = i.number("blade_length_m", 1e-3, 0.1, 0.02);
    spec.cut_force_n = i.number("cut_force_n", 0.01, 50.0, 0.0);
    if (spec.kind == InstrumentKind::scalpel && s.model != "gps" && s.model != "gps_energy" && s.model != "gps_large_strain")
      i.fail("kind", "scalpel: the organ's model '" + s.model + "' cannot follow a cut (gps, gps_energy and gps_large_strain can)");
    s.instruments.push_back(spec);
  }
  return s;
}

void reseed_regions(SceneSpec& scene, std::uint64_t seed) {
  for (std::size_t k = 0; k < scene.regions.size(); ++k)
    if (scene.regions[k].random_center) scene.regions[k].seed = seed + k;
}

SceneListing list_scenes(const std::string& directory) {
  SceneListing listing;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec)) {
    if (entry.path().extension() != ".json") continue;
    const std::string name = entry.path().stem().string();
    try {
      read_scene_file(entry.path().string());
      listing.loadable.push_back(name);
    } catch (const std::exception& e) {
      // A broken sibling never takes the server down: it is listed with its error.
      listing.unreadable.push_back({name, e.what()});
    }
  }
  std::sort(listing.loadable.begin(), listing.loadable.end());
  std::sort(listing.unreadable.begin(), listing.unreadable.end());
  return listing;
}

}  // namespace viscera::runtime
