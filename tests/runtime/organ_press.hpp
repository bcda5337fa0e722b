#pragma once  // SPDX-License-Identifier: Apache-2.0
// A scene's organ pressed by its 6 mm probe at the top centre, straight down, as the server steps
// it (the scene's organ, its probe contact, 1 ms ticks; no DDS), for the physics tests.
#include <algorithm>
#include <cmath>
#include <vector>

#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/probe_contact.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace viscera::runtime::test {

struct Press {
  double depth_m = 0;  ///< how far the tool went below its first contact
  double peak_force_n = 0, peak_edge_strain = 0;
  long most_substeps = 0;  ///< in one 1 ms tick
  /// While pressing in: the depth [m] and the force on the tool [N], one per tick.
  std::vector<double> depth_trace_m, force_trace_n;
};

/// The organ of `spec` pressed `depth_m` beyond first contact at `speed_m_s`, then held 0.3 s.
/// Throws tissue::SimulationError where the server would reset the organ.
inline Press press(const SceneSpec& spec, double depth_m, double speed_m_s = 0.02) {
  using namespace viscera::tissue;
  const auto organ = build_organ(spec, TickBudget{1e9});  // about the press, not this machine's speed
  const ProbeContact probe(organ->boundary.triangles, organ->mesh->nodes, 0.006, spec.contact_stiffness_n_per_m, 0.02, spec.contact_damping_s_per_m);
  const Box& b = organ->bounds;
  Vec3 tool(0.5 * (b.lo.x() + b.hi.x()), 0.5 * (b.lo.y() + b.hi.y()), b.hi.z() + 0.002), tool_velocity = Vec3::Zero();
  ContactResult last;
  organ->integrator->boundary_conditions().force_field = [&](const BoundaryConditions::FieldEvaluation& e) {
    last = probe.apply(tool, tool_velocity, e);
  };
  State state = State::at_rest(*organ->mesh);
  Press r;
  double contact_z = NAN;
  int held = 0;
  const double step = speed_m_s * 1e-3;
  while (held < 300) {
    const double target = std::isnan(contact_z) ? b.lo.z() : contact_z - depth_m;
    const double move = std::max(-step, target - tool.z());
    tool.z() += move;
    tool_velocity = Vec3(0, 0, move / 1e-3);
    r.most_substeps = std::max(r.most_substeps, organ->integrator->advance(state, 1e-3));
    if (std::isnan(contact_z) && last.in_contact) contact_z = tool.z();
    if (!std::isnan(contact_z)) r.depth_m = contact_z - tool.z();
    if (move == 0.0) ++held;
    r.peak_force_n = std::max(r.peak_force_n, last.force_on_tool.norm());
    r.peak_edge_strain = std::max(r.peak_edge_strain, organ->integrator->max_edge_strain());
    if (!std::isnan(contact_z) && move != 0.0) {
      r.depth_trace_m.push_back(r.depth_m);
      r.force_trace_n.push_back(last.force_on_tool.norm());
    }
  }
  return r;
}

}  // namespace viscera::runtime::test
