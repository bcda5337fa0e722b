#include "viscera/tissue/integrator/explicit_integrator.hpp"

#include <algorithm>
#include <cmath>
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
  const std::vector<double> weight = lumped_masses(model.rest_mesh(), density_kg_m3);
  if (options_.added_mass_fraction > 0) {
    scaling_ = scale_small_element_masses(model, density_kg_m3, options_.added_mass_fraction);
    mass_ = lumped_masses(model.rest_mesh(), scaling_.density_kg_m3);
  } else {
    scaling_.density_kg_m3 = std::move(density_kg_m3);
    mass_ = weight;
  }
  const auto mask = bc_.constrained_mask(mass_.size());
  critical_ = options_.global_stable_step ? global_time_step(model, mass_, mask) : critical_time_step(model, scaling_.density_kg_m3);
  dt_ = options_.dt_s > 0 ? options_.dt_s : options_.safety_factor * critical_.dt_s;
  inv_mass_.resize(mass_.size());
  gravity_.resize(mass_.size());
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    for (int k = 0; k < 3; ++k) inv_mass_[i][k] = mask[3 * i + k] ? 0.0 : 1.0 / mass_[i];
    gravity_[i] = weight[i] * bc_.gravity_m_s2;
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
  for (std::size_t i = 0; i < n; ++i) force_[i] = gravity_[i] + bc_.nodal_force(i, state.time_s);
  // Memory variables advance in place from their last evaluation to this one (a second buffer
  // would cost a third memory stream; see docs/PERFORMANCE.md). If the step then fails the
  // instability check, positions and velocities roll back but the memory stays advanced (the
  // model never writes non-finite values into it).
  const std::size_t nm = model_.memory_size();
  if (state.memory.size() != nm) state.memory.assign(nm, 0.0);
  const MemoryUpdate memory{state.memory, state.memory, state.time_s - state.memory_time_s};
  const ForceStats stats = evaluate_ ? evaluate_(state.x, force_, memory) : model_.add_forces(state.x, force_, memory);
  bool stiff_field = false;
  if (bc_.force_field) {
    std::fill(field_stiffness_.begin(), field_stiffness_.end(), 0.0);
    std::fill(field_damping_.begin(), field_damping_.end(), 0.0);
    bc_.force_field({state.x, state.v, force_, field_stiffness_, field_damping_, dt});
    stiff_field = std::any_of(field_stiffness_.begin(), field_stiffness_.end(), [](double k) { return k > 0; }) ||
                  std::any_of(field_damping_.begin(), field_damping_.end(), [](double c) { return c > 0; });
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
  x_prev_ = state.x;
  v_prev_ = state.v;
  t_prev_ = state.time_s;
  state.memory_time_s = state.time_s;
  const double damping = std::exp(-options_.mass_damping_per_s * dt);
  for (std::size_t i = 0; i < n; ++i) {
    // A node under the field's springs moves with the mass m + dt^2 k (the springs taken
    // implicitly): by Weyl's inequality dt^2 omega^2 <= dt^2 omega_model^2 + 1 <= 4 while
    // dt <= sqrt(3) / omega_model, so stiff instrument springs on light nodes never destabilise.
    // A dashpot c adds dt c (backward Euler in the velocity: a heavy dashpot stops the node, it
    // never reverses it).
    const double scale = stiff_field ? mass_[i] / (mass_[i] + dt * field_damping_[i] + dt * dt * field_stiffness_[i]) : 1.0;
    state.v[i] = (state.v[i] + (scale * dt) * inv_mass_[i].cwiseProduct(force_[i])) * damping;
    for (int k = 0; k < 3; ++k)
      if (inv_mass_[i][k] == 0.0) state.v[i][k] = 0.0;
    state.x[i] += dt * state.v[i];
  }
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
}

long ExplicitIntegrator::advance(State& state, double duration_s) {
  if (!(duration_s > 0)) return 0;
  if (!std::isfinite(dt_) || !(dt_ > 0)) throw SimulationError("the explicit step " + short_number(dt_) + " s cannot be run");
  // Equal sub-steps no longer than dt: symplectic Euler is stable at a constant step below the
  // limit, but a short last sub-step after full ones breaks its staggering and can pump energy
  // into the highest modes (seen on the 12k liver at 0.85 of the critical step).
  const long steps = static_cast<long>(std::ceil(duration_s / dt_ * (1 - 1e-12)));
  const double dt = duration_s / static_cast<double>(steps);
  const double start = state.time_s;
  max_edge_strain_ = 0.0;
  for (long k = 1; k <= steps; ++k) {
    step_with(state, dt);
    state.time_s = start + static_cast<double>(k) * dt;
    if (k < steps && interrupted_ && interrupted_()) return k;
  }
  return steps;
}

double ExplicitIntegrator::kinetic_energy(const State& state) const {
  double k = 0.0;
  for (std::size_t i = 0; i < mass_.size(); ++i) k += 0.5 * mass_[i] * state.v[i].squaredNorm();
  return k;
}

}  // namespace viscera::tissue
