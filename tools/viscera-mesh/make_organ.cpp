#include "make_organ.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/scene_file.hpp"

#include "gmsh_writer.hpp"
#include "label_fidelity.hpp"
#include "label_mesher.hpp"
#include "organ_picture.hpp"
#include "tet_quality.hpp"
#include "volume_restoration.hpp"

namespace viscera::meshing {

using common::InputError;
using json = nlohmann::ordered_json;

namespace {

constexpr std::int64_t kFewestVoxels = 27;  // a 3 x 3 x 3 block: less is noise of the segmentation, not a structure

class Stopwatch {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// Patient (RAS, metres) to the scene's frame: the table's (the patient supine: x to the patient's
/// left, y to the head, z anterior, up), centred on the organ; or the identity.
Eigen::Matrix4d scene_frame(const LabelledMesh& mesh, bool table) {
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  if (!table) return t;
  Eigen::Matrix3d r;
  r << -1, 0, 0, 0, 0, 1, 0, 1, 0;  // rows: left = -R, superior, anterior; a rotation (det +1)
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& p : mesh.nodes) {
    const Eigen::Vector3d q = r * p;
    lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  }
  t.topLeftCorner<3, 3>() = r;
  t.topRightCorner<3, 1>() = -0.5 * (lo + hi);
  return t;
}

json matrix_json(const Eigen::Matrix4d& m) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

std::string relative_to(const std::string& file, const std::string& dir) {
  return std::filesystem::relative(std::filesystem::absolute(file), std::filesystem::absolute(dir)).generic_string();
}

json instruments_json() {
  return json::array({{{"id", 1}, {"kind", "probe"}, {"tip_radius_m", 0.01}},
                      {{"id", 2}, {"kind", "probe"}, {"tip_radius_m", 0.006}},
                      {{"id", 3}, {"kind", "grasper"}, {"tip_radius_m", 0.004}, {"grasp_radius_m", 0.012}},
                      {{"id", 4}, {"kind", "scalpel"}, {"tip_radius_m", 0.001}, {"blade_length_m", 0.02}, {"cut_force_n", 1.5}}});
}

}  // namespace

int make_organ(const OrganRequest& q) {
  Stopwatch watch;
  json stages = json::object();
  const auto say = [&](const std::string& line) {
    if (!q.quiet) std::printf("viscera-mesh: %s\n", line.c_str());
    std::fflush(stdout);
  };
  // Outputs are checked before any work: a long run never ends in a refusal. The report lies in a
  // folder of its own: the server lists every .json beside a scene as a scene it can load.
  const std::filesystem::path dir(q.out_dir);
  const std::string mesh_file = (dir / (q.name + ".msh")).string(), scene_file = (dir / (q.name + ".json")).string(),
                    report_file = (dir / "reports" / (q.name + ".json")).string(), picture_file = (dir / (q.name + ".svg")).string();
  std::vector<std::string> inputs{q.label_map, q.material};
  for (const RegionLabel& r : q.regions) inputs.push_back(r.material);
  if (q.nodule_radius_m > 0) inputs.push_back(q.nodule_material);
  for (const std::string& input : inputs)
    if (!std::filesystem::is_regular_file(input)) throw InputError(input, 0, "", "no such file");
  common::create_output_folder((dir / "reports").string(), "--out");
  for (const auto& [file, what] :
       {std::pair{mesh_file, "the mesh"}, {scene_file, "the scene"}, {report_file, "the report"}, {picture_file, "the picture"}}) {
    common::refuse_existing_output(file, q.replace, "--replace");
    common::refuse_overwrite(file, inputs, what);
  }

  // 1. The label map, and the labels asked for.
  const LabelMap map = read_label_map(q.label_map);
  const auto counts = map.counts();
  std::vector<std::int32_t> labels = q.organ_labels;
  for (const RegionLabel& r : q.regions) labels.push_back(r.label);
  std::set<std::int32_t> seen;
  for (const std::int32_t l : labels) {
    if (!seen.insert(l).second) throw InputError(q.label_map, 0, "label " + std::to_string(l), "is asked for twice (--organ, --region)");
    const auto it = counts.find(l);
    if (it == counts.end() || l == 0)
      throw InputError(q.label_map, 0, "label " + std::to_string(l), "is not in the image; its labels: " + describe_labels(map));
    if (it->second < kFewestVoxels)
      throw InputError(q.label_map, 0, "label " + std::to_string(l),
                       "has " + std::to_string(it->second) + " voxels, fewer than " + std::to_string(kFewestVoxels) +
                           " (a 3 x 3 x 3 block): too small to mesh as a structure");
  }
  for (const std::int32_t l : q.hold.touching) {
    if (seen.count(l))
      throw InputError(q.label_map, 0, "label " + std::to_string(l), "is part of the organ; it cannot also hold it (--hold-touching)");
    if (!counts.count(l) || l == 0)
      throw InputError(q.label_map, 0, "label " + std::to_string(l), "is not in the image (--hold-touching); its labels: " + describe_labels(map));
  }
  std::int64_t organ_voxels = 0;
  for (const std::int32_t l : labels) organ_voxels += counts.at(l);
  const double organ_volume = static_cast<double>(organ_voxels) * map.voxel_volume_m3();
  const Eigen::Vector3d h = map.spacing_m();
  stages["read_s"] = watch.lap();
  char line[512];
  std::snprintf(line, sizeof line, "%s: %d x %d x %d voxels of %.3g x %.3g x %.3g mm; the organ's labels hold %lld voxels, %.1f mL",
                q.label_map.c_str(), map.dims[0], map.dims[1], map.dims[2], h[0] * 1e3, h[1] * 1e3, h[2] * 1e3, static_cast<long long>(organ_voxels),
                organ_volume * 1e6);
  say(line);

  // 2. The mesh: to the size asked, or to the count, the size corrected from each meshing's count.
  LabelMeshRequest m;
  m.labels = labels;
  m.seed = q.seed;
  // One voxel edge: closer, the surface chases the voxels' steps with small triangles (a shorter explicit step).
  m.facet_distance_m = q.facet_distance_m > 0 ? q.facet_distance_m : h.minCoeff();
  m.sliver_bound_deg = q.sliver_bound_deg;
  m.optimize = q.optimize;
  const double regular = 6 * std::sqrt(2.0);  // volume of a regular tetrahedron: edge^3 / (6 sqrt 2)
  m.edge_m = q.edge_m > 0 ? q.edge_m : std::cbrt(regular * organ_volume / static_cast<double>(q.target_tets));
  LabelledMesh mesh;
  json passes = json::array();
  for (int pass = 0; pass < (q.edge_m > 0 ? 1 : 4); ++pass) {
    LabelledMesh next = mesh_labels(map, m);
    const double seconds = watch.lap();
    passes.push_back({{"edge_m", m.edge_m}, {"tets", next.tets.size()}, {"seconds", seconds}});
    std::snprintf(line, sizeof line, "meshing pass %d: edge bound %.2f mm -> %zu tetrahedra, %zu nodes (%.1f s)", pass + 1, m.edge_m * 1e3,
                  next.tets.size(), next.nodes.size(), seconds);
    say(line);
    if (next.tets.empty())
      throw InputError(q.label_map, 0, "labels",
                       "CGAL's Mesh_3 made no tetrahedra of them at an edge of " + common::short_number(m.edge_m * 1e3) + " mm");
    const double ratio = static_cast<double>(next.tets.size()) / static_cast<double>(q.target_tets);
    const bool closer = mesh.tets.empty() ||
                        std::abs(std::log(ratio)) < std::abs(std::log(static_cast<double>(mesh.tets.size()) / static_cast<double>(q.target_tets)));
    if (closer) mesh = std::move(next);
    if (q.edge_m > 0 || std::abs(ratio - 1) <= 0.08) break;
    m.edge_m *= std::cbrt(ratio);
  }
  stages["mesh_s"] = 0.0;
  for (const json& p : passes) stages["mesh_s"] = stages["mesh_s"].get<double>() + p["seconds"].get<double>();

  // 3. Each label's voxel volume given back (the surface cut the voxels' corners), then the mesh
  // against the map, and its shape.
  std::vector<std::pair<std::int32_t, std::string>> names;
  for (const std::int32_t l : q.organ_labels) names.emplace_back(l, q.organ_name);
  for (const RegionLabel& r : q.regions) names.emplace_back(r.label, r.name);
  std::vector<VolumeTarget> targets;
  targets.reserve(labels.size());
  json restoration = json::array();
  for (const std::int32_t l : labels) targets.push_back({l, static_cast<double>(counts.at(l)) * map.voxel_volume_m3()});
  std::map<std::int32_t, double> meshed_volume;
  for (const std::int32_t l : labels) meshed_volume[l] = label_volume(mesh, l);
  for (const RestoredOffset& o : restore_label_volumes(mesh, targets)) {
    restoration.push_back({{"label", o.label}, {"meshed_volume_m3", meshed_volume[o.label]}, {"offset_m", o.offset_m}});
    std::snprintf(line, sizeof line, "label %d: meshed at %.2f mL, its %.2f mL of voxels given back by moving its surface %+.3f mm", o.label,
                  meshed_volume[o.label] * 1e6, static_cast<double>(counts.at(o.label)) * map.voxel_volume_m3() * 1e6, o.offset_m * 1e3);
    say(line);
  }
  json fidelity = json::array();
  const double diagonal = h.norm();
  for (const auto& [label, name] : names) {
    const LabelFidelity f = label_fidelity(map, mesh, label);
    fidelity.push_back({{"label", label},
                        {"name", name},
                        {"tets", f.tets},
                        {"voxels", counts.at(label)},
                        {"voxel_volume_m3", f.voxel_volume_m3},
                        {"mesh_volume_m3", f.mesh_volume_m3},
                        {"volume_error", f.mesh_volume_m3 / f.voxel_volume_m3 - 1},
                        {"surface_samples", f.surface_samples},
                        {"distance_mean_m", f.distance_mean_m},
                        {"distance_p95_m", f.distance_p95_m},
                        {"distance_max_m", f.distance_max_m},
                        {"voxel_diagonal_m", diagonal}});
    std::snprintf(line, sizeof line,
                  "label %d (%s): %zu tetrahedra, %.2f mL meshed for %.2f mL of voxels (%+.2f%%); surface to label boundary: mean %.2f mm, "
                  "95th percentile %.2f mm, max %.2f mm (voxel diagonal %.2f mm)",
                  label, name.c_str(), f.tets, f.mesh_volume_m3 * 1e6, f.voxel_volume_m3 * 1e6, 100 * (f.mesh_volume_m3 / f.voxel_volume_m3 - 1),
                  f.distance_mean_m * 1e3, f.distance_p95_m * 1e3, f.distance_max_m * 1e3, diagonal * 1e3);
    say(line);
  }
  const QualitySummary quality = summarize_quality(mesh.nodes, mesh.tets);
  std::snprintf(line, sizeof line,
                "quality: dihedral angles %.1f-%.1f deg (1%% below %.1f), radius-edge ratio median %.3f, max %.2f; %zu inverted or flat",
                quality.min_dihedral_deg, quality.max_dihedral_deg, quality.p1_min_dihedral_deg, quality.median_radius_edge, quality.max_radius_edge,
                quality.inverted_or_flat);
  say(line);
  stages["measure_s"] = watch.lap();

  // 4. Where it is held.
  HoldRequest hold = q.hold;
  if (hold.touch_distance_m <= 0) hold.touch_distance_m = diagonal;
  const HeldFaces held = held_faces(map, mesh, labels, hold);
  if ((!hold.touching.empty() || hold.crop) && held.faces == 0)
    throw InputError(q.label_map, 0, "--hold-touching/--hold-crop",
                     "no face of the organ's surface touches those labels or a crop plane: nothing would hold it (its surface: " +
                         std::to_string(held.surface_faces) + " faces)");
  std::snprintf(line, sizeof line, "held: %zu of %zu surface faces (%.1f of %.1f cm^2)", held.faces, held.surface_faces, held.area_m2 * 1e4,
                held.surface_area_m2 * 1e4);
  say(line);
  stages["hold_s"] = watch.lap();

  // 5. The files: the mesh in the scene's frame, the scene, the picture.
  const Eigen::Matrix4d frame = scene_frame(mesh, q.table_frame);
  LabelledMesh placed = mesh;
  for (auto& p : placed.nodes) p = frame.topLeftCorner<3, 3>() * p + frame.topRightCorner<3, 1>();
  std::vector<PhysicalGroup> groups;
  std::int32_t largest = 0;
  for (const auto& [label, name] : names) groups.push_back({label, name}), largest = std::max(largest, label);
  const bool holds = !held.tets.empty();
  const PhysicalGroup held_group{holds ? largest + 1 : 0, "held"};
  common::write_file_text(mesh_file, gmsh_text(placed, groups, held.tets, held_group));
  json regions = json::array();
  for (const RegionLabel& r : q.regions)
    regions.push_back({{"name", r.name}, {"material", relative_to(r.material, q.out_dir)}, {"elements", r.name}});
  if (q.nodule_radius_m > 0)
    regions.push_back(
        {{"name", "nodule"},
         {"material", relative_to(q.nodule_material, q.out_dir)},
         {"sphere", {{"radius_m", q.nodule_radius_m}, {"random_center", {{"seed", 1}, {"depth_m", {0.002, 0.005}}, {"facing", {0, 0, 1}}}}}}});
  json organ = {{"mesh", q.name + ".msh"},        {"scale_m_per_unit", 1},       {"material", relative_to(q.material, q.out_dir)},
                {"model", "gps_energy"},          {"stable_step", "global"},     {"volume_term", 0.5},
                {"damping_per_s", 2.0},           {"gravity_m_s2", 0},           {"contact_stiffness_n_per_m", 1000},
                {"contact_damping_s_per_m", 1.0}, {"added_mass_fraction", 0.05}, {"physics_threads", 2}};
  if (holds) organ["fix_elements"] = "held";
  if (!regions.empty()) organ["regions"] = regions;
  const json scene = {{"name", q.name}, {"domain_id", 0}, {"physics_rate_hz", 1000}, {"organ", organ}, {"instruments", instruments_json()}};
  common::write_file_text(scene_file, scene.dump(2) + "\n");
  std::vector<PictureLabel> legend;
  legend.reserve(names.size());
  for (const auto& [label, name] : names) legend.push_back({label, name});
  std::vector<char> held_flag(mesh.tets.size(), 0);
  for (const std::int32_t e : held.tets) held_flag[static_cast<std::size_t>(e)] = 1;
  std::snprintf(line, sizeof line, "%s: %zu tetrahedra from %s", q.name.c_str(), mesh.tets.size(),
                std::filesystem::path(q.label_map).filename().string().c_str());
  common::write_file_text(picture_file, organ_picture_svg(placed, legend, held_flag, line));
  stages["write_s"] = watch.lap();

  // 6. The scene loaded as the server loads it: the mesh read back and validated, the GPS constants
  // calibrated per element, the explicit step found and a sub-step timed.
  const runtime::SceneSpec spec = runtime::read_scene_file(scene_file);
  // Untimed: whether this machine runs the organ in real time is reported (the server's own line
  // below), not a reason to fail the meshing; the server applies its tick budget when it loads it.
  const auto built = runtime::build_organ(spec, runtime::TickBudget{1e9});
  const double dt = built->integrator->dt_s();
  stages["calibrate_s"] = watch.lap();
  std::snprintf(line, sizeof line, "the server's view: %s", built->describe_step(spec.physics_rate_hz).c_str());
  say(line);

  json histogram = json::array();
  for (const std::size_t n : quality.min_dihedral_histogram) histogram.push_back(n);
  double total = 0;
  for (const auto& [stage, seconds] : stages.items()) total += seconds.get<double>();
  stages["total_s"] = total;
  const auto bytes = common::read_file_bytes(q.label_map);
  const json report = {{"label_map",
                        {{"file", q.label_map},
                         {"sha256", protocol::sha256_hex(bytes)},
                         {"dims", map.dims},
                         {"spacing_m", {h[0], h[1], h[2]}},
                         {"affine_voxel_to_patient_m", matrix_json(map.affine)}}},
                       {"mesher",
                        {{"library", "CGAL Mesh_3 (labelled image domain), perturbation and exudation"},
                         {"seed", q.seed},
                         {"facet_distance_m", m.facet_distance_m},
                         {"target_tets", q.edge_m > 0 ? json(nullptr) : json(q.target_tets)},
                         {"passes", passes}}},
                       {"volume_restoration", restoration},
                       {"mesh", {{"file", mesh_file}, {"nodes", mesh.nodes.size()}, {"tets", mesh.tets.size()}}},
                       {"labels", fidelity},
                       {"quality",
                        {{"min_dihedral_deg", quality.min_dihedral_deg},
                         {"p1_min_dihedral_deg", quality.p1_min_dihedral_deg},
                         {"max_dihedral_deg", quality.max_dihedral_deg},
                         {"median_radius_edge", quality.median_radius_edge},
                         {"max_radius_edge", quality.max_radius_edge},
                         {"inverted_or_flat", quality.inverted_or_flat},
                         {"min_dihedral_histogram_5deg", histogram}}},
                       {"held",
                        {{"touching", hold.touching},
                         {"touch_distance_m", hold.touch_distance_m},
                         {"crop", hold.crop},
                         {"faces", held.faces},
                         {"surface_faces", held.surface_faces},
                         {"area_m2", held.area_m2},
                         {"surface_area_m2", held.surface_area_m2},
                         {"tets", held.tets.size()}}},
                       {"frame", {{"name", q.table_frame ? "table" : "patient"}, {"patient_to_scene_m", matrix_json(frame)}}},
                       {"calibration",
                        {{"model", spec.model},
                         {"explicit_step_s", dt},
                         {"substep_cost_s", built->substep_cost_s},
                         {"server_view", built->describe_step(spec.physics_rate_hz)}}},
                       {"scene", scene_file},
                       {"picture", picture_file},
                       {"stages_s", stages}};
  common::write_file_text(report_file, report.dump(2) + "\n");
  std::snprintf(line, sizeof line, "wrote %s, %s, %s and %s in %.1f s", mesh_file.c_str(), scene_file.c_str(), report_file.c_str(),
                picture_file.c_str(), total);
  say(line);
  return 0;
}

}  // namespace viscera::meshing
