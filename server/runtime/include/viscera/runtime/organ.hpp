#pragma once  // SPDX-License-Identifier: Apache-2.0
// The organ of a scene: its mesh, boundary surface, material, force model, explicit integrator
// and contact compliance, all built from a scene file, and rebuilt with another material while
// the server runs (session control). Building reads files and factorises; the server does it
// off the physics thread and swaps the result in between ticks.
#include <memory>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/contact_compliance.hpp"
#include "viscera/runtime/material_regions.hpp"
#include "viscera/runtime/parallel_forces.hpp"
#include "viscera/runtime/probe_contact.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/tick_budget.hpp"
#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/element/ball_strain.hpp"
#include "viscera/tissue/gps/gps_mechanisms.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::runtime {

struct Organ {
  SceneSpec scene;
  tissue::Material material;
  /// The scene's material regions on this mesh, and each region's material (region_materials[k]
  /// for regions.regions[k]); kept as they are when the organ's own material changes.
  RegionLayout regions;
  std::vector<tissue::Material> region_materials;
  std::shared_ptr<tissue::TetMesh> mesh;
  tissue::Box bounds;
  tissue::BoundarySurface boundary;
  /// The boundary triangles as the contacts see them (shared by every instrument's contact).
  std::shared_ptr<const ContactSurface> contact_surface;
  /// The tissue's strain within the scene's strain radius of a point (the instruments' tip_strain).
  std::unique_ptr<tissue::BallStrain> strain;
  /// Cuts the mesh in place (organ_cutting.hpp); null when the model cannot follow a cut.
  std::unique_ptr<tissue::MeshCutter> cutter;
  /// Changes of the boundary surface since the organ was built (SurfaceTopology's generation).
  std::uint32_t topology_generation = 0;
  /// Sweeps that changed the mesh since the organ was built.
  std::uint64_t cuts = 0;
  std::unique_ptr<tissue::ForceModel> model;
  /// What the model was made of, to make it again on a copy of the cut mesh (the compliance below).
  struct ModelRecipe {
    std::string name;  ///< the scene's model
    std::vector<tissue::Mat6> materials;  ///< the organ's (unrelaxed) elasticity, then each region's
    double volume_fraction = 0;
    tissue::GpsMechanisms mechanisms;
  } model_recipe;
  std::unique_ptr<ParallelForces> parallel_forces;  ///< on the scene's physics_threads, max(kForceChunks, threads) chunks; used by the integrator
  std::unique_ptr<tissue::ExplicitIntegrator> integrator;  ///< its force field is the caller's to set
  /// The compliance of the organ as cut by its first `next_compliance_cuts` cuts, being built on a
  /// model of its own (organ_cutting.hpp, rebuild_compliance); it replaces `compliance` once ready.
  std::unique_ptr<ContactCompliance> next_compliance;
  std::uint64_t next_compliance_cuts = 0, compliance_cuts = 0;  ///< the cuts each compliance has seen
  std::unique_ptr<ContactCompliance> compliance;  ///< last: destroyed first (its worker uses *model)
  /// One explicit sub-step of this organ on this machine [s] (the median of five, timed when built).
  double substep_cost_s = 0;
  /// The scene, mesh and material files it was built from, as read when it was built (what a
  /// recording keeps to re-run the session); a file that could not be read again is left out.
  std::vector<protocol::LoadedFile> sources;

  /// The material as the scene state shows it.
  protocol::MaterialInfo material_info() const;
  /// The material regions as the scene state shows them.
  std::vector<protocol::RegionInfo> region_info() const;
  /// One line: the explicit step, what a tick at `rate_hz` costs, and, if any, the mass scaling that
  /// lengthened the step.
  std::string describe_step(double rate_hz) const;
  /// Its material regions, one line each (empty when there is none): where each lies, how many
  /// elements it holds, its material.
  std::string describe_regions() const;
};

/// Reads the scene's mesh and material and builds the organ. Throws InputError naming the file
/// and field, also when a tick at the scene's physics rate would not fit `budget`.
std::unique_ptr<Organ> build_organ(const SceneSpec& scene, const TickBudget& budget = {});

/// The same organ (mesh shared) with some material parameters changed. Throws InputError naming
/// the parameter when the change does not apply (Young's modulus of a material that is not
/// isotropic, Q of an elastic one), gives an invalid material, or a tick that would not fit
/// `budget` at `rate_hz` (the rate the server runs at now).
std::unique_ptr<Organ> rebuild_with_material(const Organ& organ, const protocol::MaterialChange& change, double rate_hz,
                                             const TickBudget& budget = {});

}  // namespace viscera::runtime
