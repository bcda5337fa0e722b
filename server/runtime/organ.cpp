#include "viscera/runtime/organ.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <limits>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/runtime/organ_cutting.hpp"
#include "viscera/runtime/stiffening_limit.hpp"
#include "viscera/tissue/mesh/locality_order.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/refinement.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

namespace viscera::runtime {

using common::InputError;

using namespace viscera::tissue;

namespace {

/// One explicit sub-step of the organ, timed: the median of five after one to warm up [s].
double time_substep(Organ& organ) {
  State s = State::at_rest(*organ.mesh);
  organ.integrator->step(s);
  std::array<double, 5> t{};
  for (double& d : t) {
    const auto t0 = std::chrono::steady_clock::now();
    organ.integrator->step(s);
    d = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  std::nth_element(t.begin(), t.begin() + 2, t.end());
  return t[2];
}

/// The slab of the organ's bounding box whose surface nodes are fixed.
Box fixed_slab(const SceneSpec& s, const Box& bounds) {
  const int a = s.fix_axis == "x" ? 0 : s.fix_axis == "y" ? 1 : 2;
  Box slab = bounds;
  const double extent = bounds.hi[a] - bounds.lo[a];
  if (s.fix_side == "min")
    slab.hi[a] = bounds.lo[a] + s.fix_fraction * extent;
  else
    slab.lo[a] = bounds.hi[a] - s.fix_fraction * extent;
  return slab;
}

/// The scene's fixed nodes: the boundary nodes in its slab, or those of the boundary faces of its
/// fix_elements set's tetrahedra.
std::vector<std::int32_t> fixed_nodes(const Organ& organ) {
  const SceneSpec& s = organ.scene;
  if (s.fix_elements.empty()) return surface_nodes_in_box(*organ.mesh, fixed_slab(s, organ.bounds));
  const ElementSet* set = find_element_set(*organ.mesh, s.fix_elements);
  if (!set) {
    const std::string known = describe_element_sets(*organ.mesh);
    throw InputError(s.source, 0, "organ.fix_elements",
                     "'" + common::printable(s.fix_elements) + "' is not a physical group of the organ's mesh (" +
                         (known.empty() ? "it tags no volume elements" : "its volume groups: " + known) + ")");
  }
  std::vector<char> in_set(organ.mesh->tet_count(), 0);
  for (const std::int32_t e : set->tets) in_set[static_cast<std::size_t>(e)] = 1;
  std::vector<std::int32_t> nodes;
  for (std::size_t f = 0; f < organ.boundary.triangles.size(); ++f)
    if (in_set[static_cast<std::size_t>(organ.boundary.owner_tet[f])])
      nodes.insert(nodes.end(), organ.boundary.triangles[f].begin(), organ.boundary.triangles[f].end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  if (nodes.empty())
    throw InputError(
        s.source, 0, "organ.fix_elements",
        "'" + common::printable(s.fix_elements) + "': none of its tetrahedra has a face on the organ's surface; nothing would hold the organ");
  return nodes;
}

/// Model, integrator and compliance of `organ` from its scene, material and mesh, once a tick at
/// `rate_hz` is known to fit the budget (a step that cannot run is refused before any is taken).
/// `field` names what the user chose (the material file, or the parameter changed);
/// `material_source` where the material's stiffening was given.
void build_physics(Organ& organ, double rate_hz, const TickBudget& budget, const std::string& source, const std::string& field,
                   const std::string& material_source) {
  const SceneSpec& s = organ.scene;
  const Material& material = organ.material;
  Mat6 D = material.elasticity;
  GpsMechanisms ve;
  if (material.viscoelasticity) {
    const ViscoelasticSetup setup = make_viscoelastic(material.elasticity, *material.viscoelasticity, s.material);
    D = setup.unrelaxed_elasticity;
    ve = setup.gps;
  }
  // Each region's material, calibrated per element like the organ's. The relaxation is the
  // model's (one set of memory-variable weights), so a region relaxes as its organ: its own
  // material file may repeat the organ's viscoelasticity, not give another.
  std::vector<Mat6> materials{D};
  std::vector<double> density(organ.mesh->tet_count(), material.density_kg_m3);
  for (std::size_t k = 0; k < organ.region_materials.size(); ++k) {
    const Material& rm = organ.region_materials[k];
    const std::string& file = s.regions[k].material;
    if (rm.viscoelasticity && rm.viscoelasticity != material.viscoelasticity)
      throw InputError(file, 0, "viscoelasticity",
                       "differs from the organ's (" + s.material + "): a region relaxes as its organ; leave it out or give the organ's");
    materials.push_back(material.viscoelasticity ? make_viscoelastic(rm.elasticity, *material.viscoelasticity, file).unrelaxed_elasticity
                                                 : rm.elasticity);
  }
  for (std::size_t e = 0; e < organ.regions.material_of_tet.size(); ++e)
    if (const std::uint16_t m = organ.regions.material_of_tet[e]) density[e] = organ.region_materials[m - 1].density_kg_m3;
  organ.model_recipe = {s.model, materials, s.volume_term, ve};
  try {
    organ.model = make_force_model(s.model, organ.mesh, materials, s.volume_term, ve, organ.regions.material_of_tet);
  } catch (const InputError& e) {
    // The factory knows no file: the refusal names the scene's field and the material it refused.
    if (e.source() != "model") throw;
    std::string why = e.what();
    if (const std::string prefix = "model: name: "; why.starts_with(prefix)) why = why.substr(prefix.size());
    throw InputError(s.source, 0, "organ.model", why + " (material " + s.material + ")");
  }
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -s.gravity_m_s2);
  bc.fixed_nodes = fixed_nodes(organ);
  // Safety 0.85 < sqrt(3)/2: the instruments' springs are taken implicitly (force_field).
  organ.integrator = std::make_unique<ExplicitIntegrator>(
      *organ.model, density, bc, ExplicitOptions{0.85, 0.0, s.damping_per_s, 2.0, s.global_stable_step, s.added_mass_fraction});
  check_tick_budget(organ.integrator->dt_s(), 0, rate_hz, budget, source, field);
  // The same chunks on any number of threads: the same bits (a session re-simulates on another).
  organ.parallel_forces = std::make_unique<ParallelForces>(*organ.model, s.physics_threads, std::max(kForceChunks, s.physics_threads));
  organ.integrator->set_force_evaluation([p = organ.parallel_forces.get()](std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& m) {
    return p->evaluate_leaving_sums(x, f, m);
  });
  organ.integrator->set_node_loop(
      [p = organ.parallel_forces.get()](std::size_t n, const std::function<void(std::size_t, std::size_t)>& update) { p->for_ranges(n, update); });
  // The compliance predicts the simulated response, so it sees the same inertia.
  organ.substep_cost_s = time_substep(organ);
  check_tick_budget(organ.integrator->dt_s(), organ.substep_cost_s, rate_hz, budget, source, field);
  check_stiffening(ve, s.largest_edge_strain, allowed_substep_growth(organ.integrator->dt_s(), organ.substep_cost_s, rate_hz, budget),
                   material_source);
  enable_cutting(organ);  // before the compliance's worker reads the model
  organ.compliance = std::make_unique<ContactCompliance>(*organ.model, organ.integrator->mass_scaling().density_kg_m3, bc);
  // The worker reads the model while it factorises the uncut organ: a cuttable organ is ready once
  // it is done, so a scalpel cuts from the first tick, live and re-simulated alike.
  if (organ.cutter) organ.compliance->wait_settled();
  organ.contact_surface = make_contact_surface(organ.boundary.triangles, organ.mesh->nodes);
  organ.strain = std::make_unique<BallStrain>(organ.mesh, organ.scene.strain_radius_m);
}

}  // namespace

protocol::MaterialInfo Organ::material_info() const {
  protocol::MaterialInfo m;
  m.name = material.name;
  if (material.isotropic) {
    m.youngs_modulus_pa = material.isotropic->youngs_modulus_pa;
    m.poisson_ratio = material.isotropic->poisson_ratio;
  }
  m.density_kg_m3 = material.density_kg_m3;
  if (material.viscoelasticity && material.viscoelasticity->model == ViscoelasticSpec::Model::constant_q)
    m.shear_q = material.viscoelasticity->shear_q;
  m.damping_per_s = scene.damping_per_s;
  m.added_mass_fraction = integrator->mass_scaling().added_mass_fraction;
  return m;
}

std::string Organ::describe_step(double rate_hz) const {
  char b[200];
  std::snprintf(b, sizeof b, "explicit step %.3g s, forces on %d thread%s, ", integrator->dt_s(), scene.physics_threads,
                scene.physics_threads > 1 ? "s" : "");
  std::string out = b + tick_cost(integrator->dt_s(), substep_cost_s, rate_hz);
  const MassScaling& mass_scaling = integrator->mass_scaling();
  if (mass_scaling.scaled_elements > 0) {
    std::snprintf(b, sizeof b, " (mass scaling: +%.2f%% mass on %zu of %zu elements, each element's step >= %.3g s)",
                  100 * mass_scaling.added_mass_fraction, mass_scaling.scaled_elements, model->element_count(), mass_scaling.min_element_step_s);
    out += b;
  }
  return out;
}

std::vector<protocol::RegionInfo> Organ::region_info() const {
  std::vector<protocol::RegionInfo> out;
  for (std::size_t k = 0; k < regions.regions.size(); ++k) {
    const PlacedRegion& r = regions.regions[k];
    protocol::RegionInfo i;
    i.name = r.name;
    i.shape = r.shape == RegionSpec::Shape::box        ? protocol::RegionShape::box
              : r.shape == RegionSpec::Shape::elements ? protocol::RegionShape::elements
                                                       : protocol::RegionShape::sphere;
    i.center = {r.center_m.x(), r.center_m.y(), r.center_m.z()};
    i.radius_m = r.radius_m;
    i.box_min = {r.box.lo.x(), r.box.lo.y(), r.box.lo.z()};
    i.box_max = {r.box.hi.x(), r.box.hi.y(), r.box.hi.z()};
    i.depth_m = r.depth_m;
    i.elements = static_cast<std::uint32_t>(r.elements);
    i.volume_m3 = r.volume_m3;
    i.material_name = region_materials[k].name;
    if (region_materials[k].isotropic) i.youngs_modulus_pa = region_materials[k].isotropic->youngs_modulus_pa;
    out.push_back(std::move(i));
  }
  return out;
}

std::string Organ::describe_regions() const {
  std::string out;
  char b[400];
  for (std::size_t k = 0; k < regions.regions.size(); ++k) {
    const PlacedRegion& r = regions.regions[k];
    if (r.shape == RegionSpec::Shape::sphere)
      std::snprintf(b, sizeof b, "\nregion %s: sphere of radius %.4g m at (%.4g, %.4g, %.4g) m, its top %.3g m deep", r.name.c_str(), r.radius_m,
                    r.center_m.x(), r.center_m.y(), r.center_m.z(), r.depth_m);
    else if (r.shape == RegionSpec::Shape::elements)
      std::snprintf(b, sizeof b, "\nregion %s: tagged elements '%s' around (%.4g, %.4g, %.4g) m", r.name.c_str(),
                    scene.regions[k].element_set.c_str(), r.center_m.x(), r.center_m.y(), r.center_m.z());
    else
      std::snprintf(b, sizeof b, "\nregion %s: box (%.4g, %.4g, %.4g)-(%.4g, %.4g, %.4g) m", r.name.c_str(), r.box.lo.x(), r.box.lo.y(), r.box.lo.z(),
                    r.box.hi.x(), r.box.hi.y(), r.box.hi.z());
    out += b;
    std::snprintf(b, sizeof b, ", %zu elements (%.3g cm^3), material %s", r.elements, 1e6 * r.volume_m3, region_materials[k].name.c_str());
    out += b;
  }
  return out;
}

std::unique_ptr<Organ> build_organ(const SceneSpec& scene, const TickBudget& budget) {
  auto organ = std::make_unique<Organ>();
  organ->scene = scene;
  std::vector<std::pair<std::string, std::string>> files{{"scene", scene.source}, {"mesh", scene.mesh}, {"material", scene.material}};
  for (std::size_t k = 0; k < scene.regions.size(); ++k) files.emplace_back(protocol::region_material_role(k), scene.regions[k].material);
  for (const auto& [role, path] : files) {
    try {
      auto bytes = common::read_file_bytes(path);
      organ->sources.push_back({role, path, protocol::sha256_hex(bytes), std::move(bytes)});
    } catch (const InputError&) {
      // a scene made in code (tests) has no file; the mesh and material were just read
    }
  }
  organ->mesh = std::make_shared<TetMesh>(read_tet_mesh(scene.mesh));
  for (int k = 0; k < scene.refine; ++k) *organ->mesh = refine_uniform(*organ->mesh);
  // Tetrahedra along a space-filling curve, nodes in the order they last touch them: each chunk of the
  // force evaluation then writes to a narrow range of nodes (ParallelForces).
  *organ->mesh = ordered_for_locality(*organ->mesh);
  scale_mesh(*organ->mesh, scene.scale_m_per_unit);
  organ->material = read_material_file(scene.material);
  organ->bounds = bounding_box(*organ->mesh);
  organ->boundary = extract_boundary(*organ->mesh);
  // A nodule drawn at random keeps out of the fixed slab; an organ held by its own faces has no slab.
  const Box keep_out = scene.fix_elements.empty()
                           ? fixed_slab(scene, organ->bounds)
                           : Box{Vec3::Constant(std::numeric_limits<double>::infinity()), Vec3::Constant(-std::numeric_limits<double>::infinity())};
  organ->regions = lay_out_regions(scene.regions, *organ->mesh, organ->boundary, keep_out, scene.source);
  for (const RegionSpec& r : scene.regions) organ->region_materials.push_back(read_material_file(r.material));
  build_physics(*organ, scene.physics_rate_hz, budget, scene.source, "organ.material", scene.material);
  return organ;
}

std::unique_ptr<Organ> rebuild_with_material(const Organ& organ, const protocol::MaterialChange& change, double rate_hz, const TickBudget& budget) {
  auto next = std::make_unique<Organ>();
  next->scene = organ.scene;
  next->material = organ.material;
  // Its own copy of the mesh: a cuttable organ reserves room for its cuts in its mesh's vectors
  // (enable_cutting), which must not move under the live organ's physics thread.
  next->mesh = std::make_shared<TetMesh>(*organ.mesh);
  next->bounds = organ.bounds;
  next->boundary = organ.boundary;
  next->sources = organ.sources;
  next->regions = organ.regions;
  next->region_materials = organ.region_materials;
  // The request's outcome names the file; its errors name the field.
  if (change.file_text) next->material = parse_material(*change.file_text, "set_material");
  Material& m = next->material;
  const std::string source = change.file_text ? std::string("set_material") : "set_material (material " + m.name + ")";
  if (change.youngs_modulus_pa || change.poisson_ratio) {
    if (!m.isotropic) throw InputError(source, 0, change.youngs_modulus_pa ? "youngs_modulus_pa" : "poisson_ratio", "the material is not isotropic");
    if (change.youngs_modulus_pa) m.isotropic->youngs_modulus_pa = *change.youngs_modulus_pa;
    if (change.poisson_ratio) m.isotropic->poisson_ratio = *change.poisson_ratio;
    m.elasticity = elasticity_matrix(*m.isotropic, source);
  }
  if (change.density_kg_m3) m.density_kg_m3 = *change.density_kg_m3;
  if (change.shear_q) {
    if (!m.viscoelasticity || m.viscoelasticity->model != ViscoelasticSpec::Model::constant_q)
      throw InputError(source, 0, "shear_q", std::to_string(*change.shear_q) + ": the material has no constant-Q viscoelasticity");
    m.viscoelasticity->shear_q = *change.shear_q;
  }
  if (change.damping_per_s) next->scene.damping_per_s = *change.damping_per_s;
  const std::string mark = " (changed at run time)";
  if ((change.youngs_modulus_pa || change.poisson_ratio || change.shear_q || change.density_kg_m3) && !m.name.ends_with(mark)) m.name += mark;
  const char* changed = change.file_text           ? "file_text"
                        : change.youngs_modulus_pa ? "youngs_modulus_pa"
                        : change.poisson_ratio     ? "poisson_ratio"
                        : change.density_kg_m3     ? "density_kg_m3"
                        : change.shear_q           ? "shear_q"
                                                   : "damping_per_s";
  build_physics(*next, rate_hz, budget, source, changed, source);
  return next;
}

}  // namespace viscera::runtime
