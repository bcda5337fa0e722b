#include "viscera/runtime/organ_cutting.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>

#include "viscera/tissue/cutting/boundary_update.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/model/reserve_resident.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;

namespace {

GpsModel* gps_of(const Organ& organ) { return dynamic_cast<GpsModel*>(organ.model.get()); }

}  // namespace

void enable_cutting(Organ& organ) {
  const bool scalpel = std::any_of(organ.scene.instruments.begin(), organ.scene.instruments.end(),
                                   [](const InstrumentSpec& i) { return i.kind == InstrumentKind::scalpel; });
  GpsModel* gps = gps_of(organ);
  if (!scalpel || gps == nullptr) return;
  // Half as many elements again: a long incision through the 12k liver splits a few thousand.
  const std::size_t elements = organ.mesh->tet_count() * 3 / 2;
  gps->reserve_elements(elements);
  reserve_resident(organ.mesh->tets, elements);
  reserve_resident(organ.mesh->nodes, organ.mesh->node_count() * 3 / 2);
  organ.cutter = std::make_unique<MeshCutter>(*organ.mesh);
}

void reserve_for_cuts(const Organ& organ, State& state) {
  if (!organ.cutter) return;
  const std::size_t elements = organ.mesh->tets.capacity(), nodes = organ.mesh->nodes.capacity();
  reserve_resident(state.memory, gps_of(organ)->memory_size_for(elements));
  reserve_resident(state.x, nodes);
  reserve_resident(state.v, nodes);
}

bool can_cut(const Organ& organ) { return organ.cutter != nullptr; }

SweepOutcome cut_organ(Organ& organ, const BladeSweep& sweep, State& state, std::int32_t stroke) {
  SweepOutcome out;
  const CutChange change = organ.cutter->cut(sweep, state.x, stroke);
  if (!change.topology_changed()) return out;
  out.topology_changed = true;
  ++organ.cuts;
  out.tets_cut = change.replaced.size();
  out.split_edges = change.split_edges;
  out.duplicated_nodes = change.duplicated_nodes;
  const MeshEdit edit = change.edit();
  GpsModel* gps = gps_of(organ);
  // The energy the cut changes: the kinetic energy of the nodes whose mass or velocity it can change
  // (the vertices of the parents and of their children, the new nodes among them), and the
  // elastic energy of the parents (their constants, their vertices before) against that of their
  // children.
  std::vector<std::int32_t> nodes;
  for (const auto& [e, vertices] : edit.replaced) {
    out.energy_before_j += gps->element_energy(state.x, static_cast<std::size_t>(e), vertices);
    nodes.insert(nodes.end(), vertices.begin(), vertices.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  const auto kinetic = [&](std::span<const std::int32_t> of) {
    double k = 0.0;
    for (const std::int32_t n : of)
      k += 0.5 * organ.integrator->masses()[static_cast<std::size_t>(n)] * state.v[static_cast<std::size_t>(n)].squaredNorm();
    return k;
  };
  out.energy_before_j += kinetic(nodes);
  gps->follow_edit(edit, state.memory);
  out.added_mass_kg = organ.integrator->follow_edit(edit, state);
  organ.parallel_forces->follow_model();
  organ.strain->follow_edit(edit);
  const auto child = [&](std::size_t e) {
    const Tet& t = gps->element(e);
    out.energy_after_j += gps->element_energy(state.x, e, t);
    out.cut_edge_strain = std::max(out.cut_edge_strain, gps->element_max_edge_strain(state.x, e));
    nodes.insert(nodes.end(), t.begin(), t.end());
  };
  for (const auto& [e, vertices] : edit.replaced) child(static_cast<std::size_t>(e));
  for (std::size_t e = edit.elements_before; e < gps->element_count(); ++e) child(e);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  out.energy_after_j += kinetic(nodes);
  if (update_boundary(organ.boundary, *organ.cutter, change).changed()) {
    out.surface_changed = true;
    ++organ.topology_generation;
    organ.contact_surface = make_contact_surface(organ.boundary.triangles, organ.mesh->nodes);
  }
  return out;
}

namespace {

/// Each element's material as the running model has it (a cut's children take their parent's).
std::vector<std::uint16_t> element_materials(const Organ& organ) {
  const GpsModel* gps = gps_of(organ);
  std::vector<std::uint16_t> material_of(organ.mesh->tet_count());
  for (std::size_t e = 0; e < material_of.size(); ++e) material_of[e] = static_cast<std::uint16_t>(gps->material_of(e));
  return material_of;
}

std::unique_ptr<ForceModel> make_model(const Organ::ModelRecipe& r, std::shared_ptr<const TetMesh> mesh, std::vector<std::uint16_t> material_of) {
  return make_force_model(r.name, std::move(mesh), r.materials, r.volume_fraction, r.mechanisms, std::move(material_of));
}

}  // namespace

std::unique_ptr<ForceModel> remake_model(const Organ& organ) {
  if (!can_cut(organ)) throw std::logic_error("remake_model: the organ cannot be cut");
  return make_model(organ.model_recipe, std::make_shared<const TetMesh>(*organ.mesh), element_materials(organ));
}

std::unique_ptr<ContactCompliance> rebuild_compliance(const Organ& organ) {
  if (!can_cut(organ)) throw std::logic_error("rebuild_compliance: the organ cannot be cut");
  // Copied here, between ticks; calibrated and factorised on the compliance's worker.
  auto mesh = std::make_shared<const TetMesh>(*organ.mesh);
  const std::size_t nodes = mesh->node_count();
  return std::make_unique<ContactCompliance>(
      [recipe = organ.model_recipe, mesh = std::move(mesh), material_of = element_materials(organ)]() mutable {
        return make_model(recipe, std::move(mesh), std::move(material_of));
      },
      nodes, organ.integrator->mass_scaling().density_kg_m3, organ.integrator->boundary_conditions());
}

}  // namespace viscera::runtime
