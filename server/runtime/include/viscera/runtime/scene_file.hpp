#pragma once  // SPDX-License-Identifier: Apache-2.0
// Scene files (JSON, docs/SCENE.md): the organ (mesh, scale, material, model, fixed region),
// the instruments, rates and the DDS domain. Paths are relative to the scene file. Errors name
// the file and the field.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace viscera::runtime {

enum class InstrumentKind { probe, grasper, scalpel };

struct InstrumentSpec {
  std::uint32_t id = 0;
  InstrumentKind kind = InstrumentKind::probe;
  double tip_radius_m = 0.005;
  double grasp_radius_m = 0.01;  ///< grasper: surface nodes this close to the tip are grasped
  /// scalpel: the blade, a segment from the tip along the tool's z axis (the shaft) [m]; it cuts
  /// while the owner holds button 1 (blade_cuts()).
  double blade_length_m = 0.02;
  /// scalpel: the blade also cuts once its tip presses on the tissue with this force [N], until it
  /// is lifted out (PressThrough, simulated_tool.hpp); 0: only with the button
  double cut_force_n = 0.0;
};

/// Button 1 (bit 0 of Command::buttons): a scalpel's blade cuts while it is held.
inline constexpr std::uint32_t kCutButton = 1u;

/// Part of the organ made of its own material (docs/SCENE.md, "Material regions"): the elements
/// whose centroid lies inside a sphere or a box, in metres in the organ's frame (the mesh as
/// scaled), or an element set the mesh file tagged (a Gmsh physical group, by name or tag). A
/// sphere's centre may be drawn from a seed, at a depth below the surface.
struct RegionSpec {
  std::string name;
  std::string material;  ///< material file (resolved against the scene's folder)
  enum class Shape { sphere, box, elements } shape = Shape::sphere;
  std::string element_set;  ///< elements: the set's name, or its tag in decimal
  std::array<double, 3> center_m{}, lo_m{}, hi_m{};
  double radius_m = 0;
  bool random_center = false;  ///< sphere: centre drawn from `seed`
  std::uint64_t seed = 0;
  double min_depth_m = 0, max_depth_m = 0;  ///< random centre: the sphere's top this far below the surface
  /// random centre: the nearest surface faces within 60 degrees of this direction (e.g. up, where a
  /// probe palpates from); zero: any surface
  std::array<double, 3> facing{};
};

struct SceneSpec {
  std::string name, source;
  std::uint32_t domain_id = 0;
  double physics_rate_hz = 1000.0;
  double mesh_rate_hz = 60.0;  ///< surface frames per second (0: none)
  std::string mesh, material, model = "gps_energy";
  double scale_m_per_unit = 1.0, damping_per_s = 0.0, volume_term = 0.5;
  double gravity_m_s2 = 9.81;  ///< along -z
  int refine = 0;  ///< uniform 1:8 refinements of the mesh (0-2)
  bool global_stable_step = false;  ///< "stable_step": "global" | "element"
  /// Mass added to the elements with the shortest critical steps, as a fraction of the organ's
  /// mass (selective mass scaling, tissue/integrator/mass_scaling.hpp); 0: none
  double added_mass_fraction = 0.0;
  /// Threads that evaluate the organ's internal forces (the physics thread and helpers), 1-8.
  int physics_threads = 1;
  double contact_stiffness_n_per_m = 200.0;
  double contact_damping_s_per_m = 0.0;  ///< probe contact's Hunt-Crossley dashpot alpha (0: none)
  /// How instruments touch the organ: the tip's sphere as a penalty (ProbeContact), or a proxy kept
  /// on the surface with friction (ContactProxy; docs/HAPTICS.md, "The contact proxy").
  bool contact_proxy = false;
  /// Coulomb friction between the instruments and the organ's surface (the proxy's) [-]
  double contact_friction_static = 0.15, contact_friction_kinetic = 0.1;
  /// The most force the contact puts on a tool and on the tissue, whatever the depth the hand
  /// commands (the device's limit) [N]
  double contact_force_limit_n = 15.0;
  double grasp_stiffness_n_per_m = 100.0;  ///< per grasped node
  /// The radius over which the strain at an instrument is averaged (Force.tip_strain) [m]; a
  /// measure that does not depend on the mesh needs it at least 1.5 element edges (docs/TRAINING.md)
  double strain_radius_m = 0.02;
  /// The largest edge strain |L - L0| / L0 the organ must run at: a material whose stiffening
  /// could not be stepped there is refused (stiffening_limit.hpp). A 3 cm press of a 6 mm probe
  /// on the bundled livers reaches 0.35-0.43.
  double largest_edge_strain = 0.4;
  double max_tool_speed_m_s = 0.5;  ///< simulated tools follow commands at most this fast (simulated time)
  std::string fix_axis = "z", fix_side = "max";
  double fix_fraction = 0.2;
  /// When set, instead of the slab: the name or tag of an element set (physical group) of the mesh;
  /// the nodes of the boundary faces of its tetrahedra are fixed (a patient's organ where it is held,
  /// written by viscera-mesh).
  std::string fix_elements;
  std::vector<InstrumentSpec> instruments;
  std::vector<RegionSpec> regions;  ///< later regions take the elements they share with earlier ones
};

SceneSpec read_scene_file(const std::string& path);

/// Every region whose centre is drawn gets its seed from `seed` (region k: seed + k), e.g. from a
/// load_scene request: a trainer hides the nodule somewhere else on every run.
void reseed_regions(SceneSpec& scene, std::uint64_t seed);

/// The scenes of a directory: the stems of its *.json files that read as scene files (what
/// load_scene may name), and those that do not, each with its error; both sorted.
struct SceneListing {
  std::vector<std::string> loadable;
  std::vector<std::pair<std::string, std::string>> unreadable;  ///< name, error
};
SceneListing list_scenes(const std::string& directory);

}  // namespace viscera::runtime
