// The server's scalpels (docs/CUTTING.md, "In the server"): after each step, a scalpel that cuts  // SPDX-License-Identifier: Apache-2.0
// sweeps its blade from where the last tick left it to where this one does, and the organ follows
// the cut (organ_cutting.hpp). Physics thread, between the step and the snapshot.
#include <algorithm>
#include <cstdio>

#include "viscera/runtime/organ_cutting.hpp"

#include "simulation_server_impl.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;

void SimulationServer::Impl::end_stroke(std::uint32_t id, Tool& t) {
  Stroke& s = t.stroke;
  char text[320];
  std::snprintf(text, sizeof text,
                "stroke %d: %zu sweeps, %zu tetrahedra cut, %zu edges split, %zu nodes duplicated, %.3g g of inertia added; "
                "kinetic plus elastic energy rose at %zu of its %zu changes of the mesh (largest change %.3g J)",
                s.id, s.sweeps, s.tets_cut, s.split_edges, s.duplicated_nodes, 1e3 * s.added_mass_kg, s.energy_rises, s.changes,
                s.energy_change_max_j);
  event(proto::EventKind::cut_ended, id, t.tool.owner(), text);
  s = Stroke{};
}

void SimulationServer::Impl::cut_with_scalpels(const Status& status) {
  bool surface_changed = false;
  for (auto& [id, t] : tools) {
    const InstrumentSpec& spec = t.tool.spec();
    if (spec.kind != InstrumentKind::scalpel) continue;
    t.tool.update_press_through(t.result);  // the contact of the step just taken
    t.cut_edge_strain = 0;
    // A material change being built reads the mesh: the blade waits for it (a few hundred ms).
    const bool cutting = t.tool.cutting() && can_cut(*organ) && !session.preparing_material();
    Stroke& s = t.stroke;
    if (!cutting) {
      if (s.id >= 0) end_stroke(id, t);
      continue;
    }
    const Vec3 tip = t.tool.position();
    const Vec3 end = tip + spec.blade_length_m * (t.tool.orientation() * Vec3::UnitZ());
    if (s.id < 0) {  // the stroke begins where the blade is; it sweeps from the next tick on
      s.id = strokes++;
      s.blade_tip = tip;
      s.blade_end = end;
      event(proto::EventKind::cut_started, id, t.tool.owner(), "stroke " + std::to_string(s.id));
      continue;
    }
    const BladeSweep sweep{s.blade_tip, s.blade_end, tip, end};
    s.blade_tip = tip;
    s.blade_end = end;
    const SweepOutcome o = cut_organ(*organ, sweep, state, s.id);
    ++s.sweeps;
    t.cut_edge_strain = o.cut_edge_strain;
    s.tets_cut += o.tets_cut;
    s.split_edges += o.split_edges;
    s.duplicated_nodes += o.duplicated_nodes;
    s.added_mass_kg += o.added_mass_kg;
    if (o.topology_changed) {
      const double change = o.energy_after_j - o.energy_before_j;
      s.energy_change_max_j = s.changes == 0 ? change : std::max(s.energy_change_max_j, change);
      stats.cut_energy_change_max_j = stats.cut_changes == 0 ? change : std::max(stats.cut_energy_change_max_j, change);
      ++s.changes;
      ++stats.cut_changes;
      s.energy_rises += o.energy_rose();
      stats.cut_energy_rises += o.energy_rose();
    }
    surface_changed = surface_changed || o.surface_changed;
  }
  refresh_compliance(status);
  if (!surface_changed) return;
  {
    std::lock_guard world(organ_mutex);  // the command thread's queries see the new surface whole
    responder.set_surface(organ->contact_surface);
  }
  for (auto& [id, t] : tools) {
    t.contact->set_surface(organ->contact_surface);
    t.proxy.set_surface(organ->contact_surface);  // it anchors again on the cut surface, its force fading in
  }
  topology_to_publish = true;
}

void SimulationServer::Impl::refresh_compliance(const Status& status) {
  Organ& o = *organ;
  if (!can_cut(o)) return;
  const bool stroke_open = std::any_of(tools.begin(), tools.end(), [](const auto& t) { return t.second.stroke.id >= 0; });
  if (!o.next_compliance && !stroke_open && o.compliance_cuts != o.cuts) {
    o.next_compliance = rebuild_compliance(o);
    o.next_compliance_cuts = o.cuts;
    // In lockstep it takes over at this tick on every run: the same stiffness, bit for bit.
    if (lockstep) o.next_compliance->wait_settled();
  }
  if (o.next_compliance && o.next_compliance->settled()) {
    std::unique_ptr<ContactCompliance> done = std::move(o.next_compliance);  // destroyed outside the lock
    o.compliance_cuts = o.next_compliance_cuts;
    if (done->ready()) {
      std::lock_guard world(organ_mutex);  // the command thread's answers use it
      std::swap(o.compliance, done);
    } else if (status) {
      status("the cut organ's contact compliance could not be factorised (a piece cut free?): the haptic local model keeps the previous one");
    }
  }
}

}  // namespace viscera::runtime
