#include "viscera/runtime/organ_cutting.hpp"

#include <algorithm>

#include "viscera/tissue/cutting/boundary_update.hpp"
#include "viscera/tissue/gps/gps_model.hpp"

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
  gps_of(organ)->follow_edit(edit, state.memory);
  out.added_mass_kg = organ.integrator->follow_edit(edit, state);
  if (update_boundary(organ.boundary, *organ.cutter, change).changed()) {
    out.surface_changed = true;
    ++organ.topology_generation;
    organ.contact_surface = make_contact_surface(organ.boundary.triangles, organ.mesh->nodes);
  }
  return out;
}

}  // namespace viscera::runtime
