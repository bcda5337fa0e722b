#include "viscera/tissue/integrator/explicit_integrator.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

namespace viscera::tissue {

using common::short_number;

ExplicitIntegrator::ExplicitIntegrator(const ForceModel& model, std::vector<double> density_kg_m3, BoundaryConditions bc, ExplicitOptions options)
    : model_(model), bc_(std::move(bc)), options_(options) {
  if (!(options_.safety_factor > 0 && options_.safety_factor <= 1)) throw std::invalid_argument("ExplicitOptions.safety_factor must lie in (0, 1]");
  if (!(options_.mass_damping_per_s >= 0)) throw std::invalid_argument("ExplicitOptions.mass_damping_per_s must be >= 0");
  weight_ = lumped_masses(model.rest_mesh(), density_kg_m3);
  density_ = density_kg_m3;
  if (options_.added_mass_fraction > 0) {
    scaling_ = scale_small_element_masses(model, density_kg_m3, options_.added_mass_fraction);
    mass_ = lumped_masses(model.rest_mesh(), scaling_.density_kg_m3);
  } else {
    scaling_.density_kg_m3 = std::move(density_kg_m3);
    mass_ = weight_;
  }
  constrained_ = bc_.constrained_mask(mass_.size());
  critical_ = options_.global_stable_step ? global_time_step(model, mass_, constrained_) : critical_time_step(model, scaling_.density_kg_m3);
  // What an edit holds its changed elements to (element_step_s): the element bound, or with the
  // global estimate the organ's critical step itself (an element whose own step were only the
  // organ's worst element's, 2-3x below the global step, rang up the cut liver within 20 steps).
  element_step_s_ = options_.global_stable_step ? critical_.dt_s : 2.0 / critical_.omega_max_rad_s;
  dt_ = options_.dt_s > 0 ? options_.dt_s : options_.safety_factor * critical_.dt_s;
  inv_mass_.resize(mass_.size());
  gravity_.resize(mass_.size());
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    for (int k = 0; k < 3; ++k) inv_mass_[i][k] = constrained_[3 * i + k] ? 0.0 : 1.0 / mass_[i];
    gravity_[i] = weight_[i] * bc_.gravity_m_s2;
  }
  if (!bc_.nodal_forces.empty() && bc_.nodal_forces.size() != mass_.size())
    throw std::invalid_argument("BoundaryConditions.nodal_forces: one force per node expected");
  force_.resize(mass_.size());
  field_stiffness_.resize(mass_.size());
  field_damping_.resize(mass_.size());
}

void ExplicitIntegrator::step(State& state) { step_with(state, dt_); }

void ExplicitIntegrator::step_with(State& state, double dt) {
  const std::size_t n = mass_.size();
  if (bc_.nodal_forces.empty())
    std::copy(gravity_.begin(), gravity_.end(), force_.begin());
  else
    for (std::size_t i = 0; i < n; ++i) force_[i] = gravity_[i] + bc_.nodal_force(i, state.time_s);
  // Memory variables advance in place from their last evaluation to this one (a second buffer
  // would cost a third memory stream; see docs/PERFORMANCE.md). If the step then fails the
  // instability check, positions and velocities roll back but the memory stays advanced (the
  // model never writes non-finite values into it).
  const std::size_t nm = model_.memory_size();
  if (state.memory.size() != nm) state.memory.assign(nm, 0.0);
  const MemoryUpdate memory{state.memory, state.memory, state.time_s - state.memory_time_s};
  const ForceStats stats = evaluate_ ? evaluate_(state.x, force_, memory) : model_.add_forces(state.x, force_, memory);
  const bool field = static_cast<bool>(bc_.force_field);
  if (field) {
    std::fill(field_stiffness_.begin(), field_stiffness_.end(), 0.0);
    std::fill(field_damping_.begin(), field_damping_.end(), 0.0);
    bc_.force_field({state.x, state.v, force_, field_stiffness_, field_damping_, dt});
  }
  if (!(stats.max_edge_strain <= options_.max_edge_strain)) {
    const std::size_t e = find_max_strain_element(model_, state.x);
    std::ostringstream msg;
    msg << "explicit integration went unstable at t = " << state.time_s << " s: element " << e << " has edge strain "
        << model_.element_max_edge_strain(state.x, e) << " (limit " << options_.max_edge_strain << "); dt = " << dt << " s, critical step "
        << critical_.dt_s << " s";
    if (!x_prev_.empty()) {  // back to the last state that passed this check
      state.x = x_prev_;
      state.v = v_prev_;
      state.time_s = t_prev_;
    }
    throw SimulationError(msg.str());
  }
  max_edge_strain_ = std::max(max_edge_strain_, stats.max_edge_strain);
  last_edge_strain_ = stats.max_edge_strain;
  t_prev_ = state.time_s;
  state.memory_time_s = state.time_s;
  x_prev_.resize(n);
  v_prev_.resize(n);
  const double damping = std::exp(-options_.mass_damping_per_s * dt);
  // Each range of nodes: the state this step starts from is kept (the roll-back's), then moved.
  const auto update = [&](std::size_t first, std::size_t last) {
    Vec3* x = state.x.data();
    Vec3* v = state.v.data();
    const Vec3 *f = force_.data(), *inv_mass = inv_mass_.data();
    const double* mass = mass_.data();
    const double* stiffness = field ? field_stiffness_.data() : nullptr;
    const double* dashpot = field_damping_.data();
    // Copied ahead of the loop, not in it: a loop of fewer streams (4 us less a tick on the 12k liver).
    std::copy(x + first, x + last, x_prev_.data() + first);
    std::copy(v + first, v + last, v_prev_.data() + first);
    for (std::size_t i = first; i < last; ++i) {
      // A node under the field's springs moves with the mass m + dt^2 k (the springs taken
      // implicitly): by Weyl's inequality dt^2 omega^2 <= dt^2 omega_model^2 + 1 <= 4 while
      // dt <= sqrt(3) / omega_model, so stiff instrument springs on light nodes never destabilise.
      // A dashpot c adds dt c (backward Euler in the velocity: a heavy dashpot stops the node, it
      // never reverses it).
      double scale = 1.0;
      if (stiffness)
        if (const double k = stiffness[i], c = dashpot[i]; k > 0 || c > 0) scale = mass[i] / (mass[i] + dt * c + dt * dt * k);
      Vec3 vi = (v[i] + (scale * dt) * inv_mass[i].cwiseProduct(f[i])) * damping;
      for (int a = 0; a < 3; ++a)
        if (inv_mass[i][a] == 0.0) vi[a] = 0.0;
      v[i] = vi;
      x[i] += dt * vi;
    }
  };
  if (for_nodes_)
    for_nodes_(n, std::cref(update));  // by reference: no allocation a sub-step
  else
    update(0, n);
  const double t1 = state.time_s + dt;
  const auto& rest = model_.rest_mesh().nodes;
  for (const auto& p : bc_.prescribed)
    for (auto i : p.nodes) {
      const Vec3 target = p.position(rest[i], t1);
      state.v[i] = (target - x_prev_[i]) / dt;
      state.x[i] = target;
    }
  for (const auto& p : bc_.prescribed_axes)
    for (auto i : p.nodes) {
      const double target = p.coordinate(rest[i], t1);
      state.v[i][p.axis] = (target - x_prev_[i][p.axis]) / dt;
      state.x[i][p.axis] = target;
    }
  state.time_s = t1;
  last_step_end_s_ = t1;
}

double ExplicitIntegrator::stiffened_step_s() const {
  // The strain the next sub-step starts from is near the last one's.
  return dt_ / std::sqrt(model_.stiffness_growth(headroom_strain(last_edge_strain_)));
}

long ExplicitIntegrator::advance(State& state, double duration_s) {
  if (!(duration_s > 0)) return 0;
  if (!std::isfinite(dt_) || !(dt_ > 0)) throw SimulationError("the explicit step " + short_number(dt_) + " s cannot be run");
  // Equal sub-steps no longer than dt: symplectic Euler is stable at a constant step below the
  // limit, but a short last sub-step after full ones breaks its staggering and can pump energy
  // into the highest modes (seen on the 12k liver at 0.85 of the critical step). When the
  // stiffened tissue needs shorter ones mid-way, what is left is divided into equal ones again.
  const auto sub_steps = [this](double duration, double longest) {
    if (!(longest * kMaxStiffenedSubSteps >= dt_))
      throw SimulationError("explicit integration went unstable: at edge strain " + short_number(last_edge_strain_) + " the tissue is " +
                            short_number(model_.stiffness_growth(headroom_strain(last_edge_strain_))) +
                            " times as stiff as at rest, its stable step " + short_number(longest) + " s is below dt / " +
                            short_number(kMaxStiffenedSubSteps));
    return std::max(1L, static_cast<long>(std::ceil(duration / longest * (1 - 1e-12))));
  };
  if (state.time_s != last_step_end_s_) last_edge_strain_ = 0.0;  // a state not left by the last step (reset, reloaded)
  const double start = state.time_s, end = start + duration_s;
  double from = start;  // where the current division into equal sub-steps began
  long steps = sub_steps(duration_s, std::min(dt_, stiffened_step_s()));
  double dt = duration_s / static_cast<double>(steps);
  long done = 0, since = 0;  // sub-steps taken, of them in the current division
  max_edge_strain_ = 0.0;
  while (done < steps) {
    step_with(state, dt);
    ++done;
    ++since;
    state.time_s = last_step_end_s_ = from + static_cast<double>(since) * dt;
    if (done == steps) break;
    if (const double longest = stiffened_step_s(); dt > longest) {
      from = state.time_s;
      since = 0;
      const long rest = sub_steps(end - from, longest);
      steps = done + rest;
      dt = (end - from) / static_cast<double>(rest);
    }
    if (interrupted_ && interrupted_()) return done;
  }
  return steps;
}

double ExplicitIntegrator::gravity_energy(std::span<const Vec3> x) const {
  double e = 0.0;
  for (std::size_t i = 0; i < weight_.size(); ++i) e -= weight_[i] * bc_.gravity_m_s2.dot(x[i]);
  return e;
}

double ExplicitIntegrator::follow_edit(const MeshEdit& edit, State& state) {
  const std::size_t nodes = model_.node_count(), elements = model_.element_count();
  if (edit.nodes_before != mass_.size() || edit.nodes_before + edit.new_nodes.size() != nodes || edit.elements_before != density_.size() ||
      edit.origin.size() != elements || state.x.size() != edit.nodes_before || state.v.size() != edit.nodes_before)
    throw std::invalid_argument("ExplicitIntegrator::follow_edit: the edit does not match the integrator, its model or the state");
  const auto& X = model_.rest_mesh().nodes;
  const auto& tets = model_.rest_mesh().tets;
  // New nodes: state, flags and empty masses.
  mass_.resize(nodes, 0.0);
  weight_.resize(nodes, 0.0);
  constrained_.resize(3 * nodes, 0);
  for (std::size_t k = 0; k < edit.new_nodes.size(); ++k) {
    const MeshEdit::NewNode& n = edit.new_nodes[k];
    const auto a = static_cast<std::size_t>(n.a), b = static_cast<std::size_t>(n.b), i = edit.nodes_before + k;
    state.x.push_back((1.0 - n.t) * state.x[a] + n.t * state.x[b]);
    state.v.push_back((1.0 - n.t) * state.v[a] + n.t * state.v[b]);
    bool fixed = false;
    for (int c = 0; c < 3; ++c) {
      constrained_[3 * i + static_cast<std::size_t>(c)] =
          constrained_[3 * a + static_cast<std::size_t>(c)] && constrained_[3 * b + static_cast<std::size_t>(c)];
      fixed = fixed || constrained_[3 * i + static_cast<std::size_t>(c)] != 0;
    }
    if (fixed) bc_.fixed_nodes.push_back(static_cast<std::int32_t>(i));
    if (!bc_.nodal_forces.empty()) bc_.nodal_forces.push_back(Vec3::Zero());
  }
  // Lumped masses: the replaced elements' shares off, the changed and new elements' on.
  std::vector<double>& inertia = scaling_.density_kg_m3;
  const auto share = [&](const Tet& t, double density) { return 0.25 * density * signed_volume(X[t[0]], X[t[1]], X[t[2]], X[t[3]]); };
  // The changed elements in ascending order (the replaced, then the new ones), without a pass over
  // the whole organ: a sweep of the 12k liver changes a few tens of its elements.
  std::vector<std::int32_t> changed;
  changed.reserve(edit.replaced.size() + (elements - edit.elements_before));
  for (const auto& [e, t] : edit.replaced) {
    changed.push_back(e);
    const double w = share(t, density_[static_cast<std::size_t>(e)]), m = share(t, inertia[static_cast<std::size_t>(e)]);
    for (const std::int32_t v : t) {
      weight_[static_cast<std::size_t>(v)] -= w;
      mass_[static_cast<std::size_t>(v)] -= m;
    }
  }
  std::sort(changed.begin(), changed.end());
  for (std::size_t e = edit.elements_before; e < elements; ++e) changed.push_back(static_cast<std::int32_t>(e));
  for (std::size_t e = edit.elements_before; e < elements; ++e) {
    const auto p = static_cast<std::size_t>(edit.origin[e]);
    density_.push_back(density_[p]);
    inertia.push_back(inertia[p]);
  }
  // Local mass scaling: every changed element's own step back to the organ's element step.
  std::vector<double> unscaled(changed.size());
  for (std::size_t k = 0; k < changed.size(); ++k) unscaled[k] = inertia[static_cast<std::size_t>(changed[k])];
  const double added = hold_element_steps(model_, inertia, changed, element_step_s_);
  grown_.resize(nodes, 0.0);  // inertia added per node (all 0 between edits)
  std::vector<std::int32_t> touched;  // the changed elements' nodes
  touched.reserve(4 * changed.size());
  for (std::size_t k = 0; k < changed.size(); ++k) {
    const auto e = static_cast<std::size_t>(changed[k]);
    const Tet& t = tets[e];
    const double w = share(t, density_[e]), m = share(t, inertia[e]), m0 = share(t, unscaled[k]);
    for (const std::int32_t v : t) {
      weight_[static_cast<std::size_t>(v)] += w;
      mass_[static_cast<std::size_t>(v)] += m;
      grown_[static_cast<std::size_t>(v)] += m - m0;
      touched.push_back(v);
    }
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  // Momentum kept where inertia was added; the touched nodes' gravity and inverse masses.
  gravity_.resize(nodes);
  inv_mass_.resize(nodes);
  for (const std::int32_t element : changed)
    for (const std::int32_t v : tets[static_cast<std::size_t>(element)]) {
      const auto i = static_cast<std::size_t>(v);
      gravity_[i] = weight_[i] * bc_.gravity_m_s2;
      for (int c = 0; c < 3; ++c) inv_mass_[i][c] = constrained_[3 * i + static_cast<std::size_t>(c)] ? 0.0 : 1.0 / mass_[i];
    }
  for (const std::int32_t v : touched) {
    const auto i = static_cast<std::size_t>(v);
    if (grown_[i] > 0.0) state.v[i] *= (mass_[i] - grown_[i]) / mass_[i];
    grown_[i] = 0.0;
  }
  force_.resize(nodes);
  field_stiffness_.resize(nodes);
  field_damping_.resize(nodes);
  x_prev_.clear();  // no roll-back across an edit
  v_prev_.clear();
  return added;
}

double ExplicitIntegrator::kinetic_energy(const State& state) const {
  double k = 0.0;
  for (std::size_t i = 0; i < mass_.size(); ++i) k += 0.5 * mass_[i] * state.v[i].squaredNorm();
  return k;
}

}  // namespace viscera::tissue
