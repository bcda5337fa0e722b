#include "viscera/runtime/organ_cutting.hpp"

#include <algorithm>

#include "viscera/tissue/cutting/boundary_update.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/model/model_factory.hpp"

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
  organ.mesh->tets.reserve(elements);
  organ.mesh->nodes.reserve(organ.mesh->node_count() * 3 / 2);
  organ.cutter = std::make_unique<MeshCutter>(*organ.mesh);
}

void reserve_for_cuts(const Organ& organ, State& state) {
  if (!organ.cutter) return;
  const std::size_t elements = organ.mesh->tets.capacity(), nodes = organ.mesh->nodes.capacity();
  state.memory.reserve(gps_of(organ)->memory_size_for(elements));
  state.x.reserve(nodes);
  state.v.reserve(nodes);
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
  // The energy the cut changes: the kinetic energy (masses and new nodes), and the elastic energy
  // of the parents (their constants, their vertices before) against that of their children.
  out.energy_before_j = organ.integrator->kinetic_energy(state);
  for (const auto& [e, vertices] : edit.replaced) out.energy_before_j += gps->element_energy(state.x, static_cast<std::size_t>(e), vertices);
  gps->follow_edit(edit, state.memory);
  out.added_mass_kg = organ.integrator->follow_edit(edit, state);
  out.energy_after_j = organ.integrator->kinetic_energy(state);
  for (const auto& [e, vertices] : edit.replaced)
    out.energy_after_j += gps->element_energy(state.x, static_cast<std::size_t>(e), gps->element(static_cast<std::size_t>(e)));
  for (std::size_t e = edit.elements_before; e < gps->element_count(); ++e) out.energy_after_j += gps->element_energy(state.x, e, gps->element(e));
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
