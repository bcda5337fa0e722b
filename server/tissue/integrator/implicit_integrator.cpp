#include "viscera/tissue/integrator/implicit_integrator.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

namespace viscera::tissue {

namespace {
double norm(const std::vector<double>& r) {
  double s = 0.0;
  for (double v : r) s += v * v;
  return std::sqrt(s);
}
}  // namespace

ImplicitIntegrator::ImplicitIntegrator(const ForceModel& model, std::vector<double> density_kg_m3, BoundaryConditions bc, ImplicitOptions options)
    : model_(model), bc_(std::move(bc)), options_(options) {
  if (!(options_.dt_s > 0)) throw std::invalid_argument("ImplicitOptions.dt_s must be > 0");
  density_ = std::move(density_kg_m3);
  mass_ = lumped_masses(model.rest_mesh(), density_);
  const std::size_t n = mass_.size();
  if (!bc_.nodal_forces.empty() && bc_.nodal_forces.size() != n)
    throw std::invalid_argument("BoundaryConditions.nodal_forces: one force per node expected");
  // Largest diagonal stiffness at rest: with the largest displacement it gives the size of the
  // element forces, whose round-off bounds how small a residual can get.
  for (std::size_t e = 0; e < model.element_count(); ++e)
    stiffness_scale_ = std::max(stiffness_scale_, model.element_tangent(model.rest_mesh().nodes, e).diagonal().cwiseAbs().maxCoeff());
  analyse_pattern();
}

void ImplicitIntegrator::analyse_pattern() {
  const std::size_t n = mass_.size();
  external_.resize(n);
  force_.resize(n);
  const auto mask = bc_.constrained_mask(n);
  dof_.assign(3 * n, -1);
  free_dofs_ = 0;
  for (std::size_t c = 0; c < 3 * n; ++c)
    if (!mask[c]) dof_[c] = free_dofs_++;
  solver_.reset();
  element_slots_.clear();
  diagonal_slots_.clear();
  ++pattern_analyses_;
  if (free_dofs_ == 0) return;

  // Sparsity pattern of the upper triangle over free dofs: 3x3 blocks between nodes of a tet.
  std::vector<std::vector<int>> rows(static_cast<std::size_t>(free_dofs_));
  for (std::size_t e = 0; e < model_.element_count(); ++e) {
    const Tet& t = model_.element(e);
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q) {
        const int dp = dof_[3 * t[p / 3] + p % 3], dq = dof_[3 * t[q / 3] + q % 3];
        if (dp >= 0 && dq >= 0 && dp <= dq) rows[static_cast<std::size_t>(dq)].push_back(dp);
      }
  }
  std::vector<int> colptr(1, 0), rowidx;
  for (auto& r : rows) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    rowidx.insert(rowidx.end(), r.begin(), r.end());
    colptr.push_back(static_cast<int>(rowidx.size()));
  }
  solver_ = std::make_unique<SparseCholesky>(free_dofs_, std::move(colptr), std::move(rowidx));
  element_slots_.assign(144 * model_.element_count(), -1);
  for (std::size_t e = 0; e < model_.element_count(); ++e) {
    const Tet& t = model_.element(e);
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q) {
        const int r = dof_[3 * t[p / 3] + p % 3], c = dof_[3 * t[q / 3] + q % 3];
        if (r >= 0 && c >= 0 && r <= c) element_slots_[144 * e + 12 * p + q] = solver_->slot(r, c);
      }
  }
  diagonal_slots_.resize(static_cast<std::size_t>(free_dofs_));
  for (int d = 0; d < free_dofs_; ++d) diagonal_slots_[static_cast<std::size_t>(d)] = solver_->slot(d, d);
}

void ImplicitIntegrator::follow_edit(const MeshEdit& edit, State& state) {
  const std::size_t nodes = model_.node_count(), elements = model_.element_count();
  if (edit.nodes_before != mass_.size() || edit.nodes_before + edit.new_nodes.size() != nodes || edit.elements_before != density_.size() ||
      edit.origin.size() != elements || state.x.size() != edit.nodes_before || state.v.size() != edit.nodes_before)
    throw std::invalid_argument("ImplicitIntegrator::follow_edit: the edit does not match the integrator, its model or the state");
  std::vector<NewNodeEnds> ends;
  ends.reserve(edit.new_nodes.size());
  for (const MeshEdit::NewNode& n : edit.new_nodes) {
    const auto a = static_cast<std::size_t>(n.a), b = static_cast<std::size_t>(n.b);
    state.x.push_back((1.0 - n.t) * state.x[a] + n.t * state.x[b]);
    state.v.push_back((1.0 - n.t) * state.v[a] + n.t * state.v[b]);
    ends.push_back({n.a, n.b});
  }
  extend_constraints(bc_, ends, edit.nodes_before);
  for (std::size_t e = edit.elements_before; e < elements; ++e) density_.push_back(density_[static_cast<std::size_t>(edit.origin[e])]);
  mass_ = lumped_masses(model_.rest_mesh(), density_);
  const auto& rest = model_.rest_mesh().nodes;
  const auto rescale = [&](std::size_t e) {
    stiffness_scale_ = std::max(stiffness_scale_, model_.element_tangent(rest, e).diagonal().cwiseAbs().maxCoeff());
  };
  for (const auto& [e, before] : edit.replaced) rescale(static_cast<std::size_t>(e));
  for (std::size_t e = edit.elements_before; e < elements; ++e) rescale(e);
  // The pattern changed (new nodes, new elements): analysed again, once, here; the steps after
  // reuse it, refactorising numerically only.
  analyse_pattern();
}

ImplicitIntegrator::~ImplicitIntegrator() = default;

void ImplicitIntegrator::apply_constraints(State& state, double t) {
  const auto& rest = model_.rest_mesh().nodes;
  for (auto i : bc_.fixed_nodes) state.x[i] = rest[i];
  for (const auto& c : bc_.fixed_axes) state.x[c.node][c.axis] = rest[c.node][c.axis];
  for (const auto& p : bc_.prescribed)
    for (auto i : p.nodes) state.x[i] = p.position(rest[i], t);
  for (const auto& p : bc_.prescribed_axes)
    for (auto i : p.nodes) state.x[i][p.axis] = p.coordinate(rest[i], t);
}

double ImplicitIntegrator::residual(const std::vector<Vec3>& x, bool dynamic, const std::vector<Vec3>& x_n, const std::vector<Vec3>& v_n,
                                    std::vector<double>& r) {
  std::fill(force_.begin(), force_.end(), Vec3::Zero());
  if (dynamic && memory_before_) {
    memory_trial_.resize(memory_before_->size());
    model_.add_forces(x, force_, {*memory_before_, memory_trial_, options_.dt_s});
  } else {
    model_.add_forces(x, force_);
  }
  const double dt = options_.dt_s;
  const double mass_scale = (1.0 + options_.mass_damping_per_s * dt) / (dt * dt);
  r.assign(static_cast<std::size_t>(free_dofs_), 0.0);
  internal_norm_ = 0.0;
  for (std::size_t c = 0; c < dof_.size(); ++c)
    if (dof_[c] >= 0) internal_norm_ += force_[c / 3][c % 3] * force_[c / 3][c % 3];
  internal_norm_ = std::sqrt(internal_norm_);
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    Vec3 ri = -force_[i] - external_[i];
    if (dynamic) ri += mass_[i] * (mass_scale * (x[i] - x_n[i]) - v_n[i] / dt);
    for (int k = 0; k < 3; ++k)
      if (dof_[3 * i + k] >= 0) r[static_cast<std::size_t>(dof_[3 * i + k])] = ri[k];
  }
  return norm(r);
}

void ImplicitIntegrator::assemble(const std::vector<Vec3>& x, double mass_scale, double regularisation) {
  std::span<double> values = solver_->values();
  std::fill(values.begin(), values.end(), 0.0);
  for (std::size_t e = 0; e < model_.element_count(); ++e) {
    const Mat12 K = mass_scale <= 0  ? model_.element_tangent(x, e)
                    : memory_before_ ? model_.element_tangent(x, e, options_.dt_s, *memory_before_)
                                     : model_.element_tangent(x, e, options_.dt_s);
    const long* slots = &element_slots_[144 * e];
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q)
        if (slots[12 * p + q] >= 0) values[static_cast<std::size_t>(slots[12 * p + q])] += 0.5 * (K(p, q) + K(q, p));
  }
  double mean_diagonal = 0.0;
  for (std::size_t c = 0; c < dof_.size(); ++c)
    if (dof_[c] >= 0) values[static_cast<std::size_t>(diagonal_slots_[static_cast<std::size_t>(dof_[c])])] += mass_scale * mass_[c / 3];
  if (regularisation > 0) {
    for (long s : diagonal_slots_) mean_diagonal += values[static_cast<std::size_t>(s)];
    mean_diagonal /= static_cast<double>(diagonal_slots_.size());
    for (long s : diagonal_slots_) values[static_cast<std::size_t>(s)] += regularisation * mean_diagonal;
  }
}

bool ImplicitIntegrator::factorize_stiffness(const std::vector<Vec3>& x) {
  if (!solver_) return false;
  assemble(x, 0.0, 0.0);
  return solver_->factorize();
}

void ImplicitIntegrator::compliance(std::span<const Vec3> f, std::span<Vec3> u) {
  std::vector<double> b(static_cast<std::size_t>(free_dofs_)), y(b.size());
  for (std::size_t c = 0; c < dof_.size(); ++c)
    if (dof_[c] >= 0) b[static_cast<std::size_t>(dof_[c])] = f[c / 3][static_cast<int>(c % 3)];
  solver_->solve(b, y);
  for (std::size_t c = 0; c < dof_.size(); ++c) u[c / 3][static_cast<int>(c % 3)] = dof_[c] >= 0 ? y[static_cast<std::size_t>(dof_[c])] : 0.0;
}

void ImplicitIntegrator::update_external(double t) {
  for (std::size_t i = 0; i < mass_.size(); ++i) external_[i] = mass_[i] * bc_.gravity_m_s2 + bc_.nodal_force(i, t);
}

NewtonReport ImplicitIntegrator::newton(State& state, bool dynamic, const std::vector<Vec3>& x_n, const std::vector<Vec3>& v_n) {
  NewtonReport rep;
  std::vector<double> r, dx(static_cast<std::size_t>(free_dofs_));
  double rn = residual(state.x, dynamic, x_n, v_n, r);
  memory_accepted_.swap(memory_trial_);
  rep.initial_residual_n = rn;
  double ext = 0.0;
  for (std::size_t c = 0; c < dof_.size(); ++c)
    if (dof_[c] >= 0) ext += external_[c / 3][c % 3] * external_[c / 3][c % 3];
  // Scale of the forces in play: residual, loads, and the internal forces (whose round-off sets
  // the floor the residual can reach).
  double displacement = 0.0;
  for (std::size_t i = 0; i < state.x.size(); ++i)
    displacement = std::max(displacement, (state.x[i] - model_.rest_mesh().nodes[i]).cwiseAbs().maxCoeff());
  rep.force_scale_n = std::max({rn, std::sqrt(ext), internal_norm_, stiffness_scale_ * displacement});
  const double dt = options_.dt_s;
  const double mass_scale = dynamic ? (1.0 + options_.mass_damping_per_s * dt) / (dt * dt) : 0.0;
  std::vector<Vec3> trial;
  const double tolerance = std::max(options_.relative_tolerance * rep.force_scale_n, options_.absolute_tolerance_n);
  const auto converged = [&] { return rn <= tolerance; };
  while (!converged() && rep.iterations < options_.max_iterations) {
    ++rep.iterations;
    const double rn_before = rn;
    double reg = 0.0;
    assemble(state.x, mass_scale, reg);
    while (!solver_->factorize()) {
      ++rep.regularised_factorisations;
      reg = reg == 0.0 ? 1e-8 : reg * 10.0;
      if (reg > 1e3) throw SimulationError("implicit step: tangent cannot be factorised even regularised");
      assemble(state.x, mass_scale, reg);
    }
    solver_->solve(r, dx);
    double alpha = 1.0;
    for (int ls = 0; ls < 12; ++ls, alpha *= 0.5) {
      trial = state.x;
      for (std::size_t c = 0; c < dof_.size(); ++c)
        if (dof_[c] >= 0) trial[c / 3][c % 3] -= alpha * dx[static_cast<std::size_t>(dof_[c])];
      std::vector<double> r_trial;
      const double rt = residual(trial, dynamic, x_n, v_n, r_trial);
      if (rt < rn || ls == 11) {
        state.x.swap(trial);
        r.swap(r_trial);
        memory_accepted_.swap(memory_trial_);
        rn = rt;
        break;
      }
    }
    // Round-off floor: a Newton step that no longer halves an already tiny residual, or one too
    // small to change the positions' representation (the linear solve's accuracy is reached).
    double step = 0.0, size = 0.0;
    for (std::size_t c = 0; c < dof_.size(); ++c)
      if (dof_[c] >= 0) step = std::max(step, std::abs(dx[static_cast<std::size_t>(dof_[c])]));
    for (const Vec3& p : state.x) size = std::max(size, p.cwiseAbs().maxCoeff());
    if (!converged() && rn <= 1e-6 * rep.force_scale_n && (rn > 0.5 * rn_before || step <= 1e-14 * size)) {
      rep.roundoff_limited = true;
      break;
    }
  }
  rep.residual_n = rn;
  rep.converged = converged() || rep.roundoff_limited;
  return rep;
}

NewtonReport ImplicitIntegrator::step(State& state) {
  const double dt = options_.dt_s;
  const std::vector<Vec3> x_n = state.x, v_n = state.v;
  const std::size_t nm = model_.memory_size();
  if (state.memory.size() != nm) state.memory.assign(nm, 0.0);
  if (nm > 0 && state.memory_time_s != state.time_s) {
    // Memory must belong to the start of the step: bring it there at the current positions.
    std::vector<Vec3> f(mass_.size(), Vec3::Zero());
    std::vector<double> m(nm);
    model_.add_forces(state.x, f, {state.memory, m, state.time_s - state.memory_time_s});
    state.memory.swap(m);
    state.memory_time_s = state.time_s;
  }
  memory_before_ = nm > 0 ? &state.memory : nullptr;
  for (std::size_t i = 0; i < mass_.size(); ++i) state.x[i] += dt * state.v[i];  // predictor
  apply_constraints(state, state.time_s + dt);
  update_external(state.time_s + dt);
  NewtonReport rep = free_dofs_ > 0 ? newton(state, true, x_n, v_n) : NewtonReport{0, 0, 0, 0, 0, true, false};
  if (!rep.converged) {
    std::ostringstream msg;
    msg << "implicit step at t = " << state.time_s << " s did not converge in " << rep.iterations << " Newton iterations: residual " << rep.residual_n
        << " N (tolerance " << std::max(options_.relative_tolerance * rep.force_scale_n, options_.absolute_tolerance_n) << " N)";
    state.x = x_n;
    state.v = v_n;
    memory_before_ = nullptr;
    throw SimulationError(msg.str());
  }
  for (std::size_t i = 0; i < mass_.size(); ++i) state.v[i] = (state.x[i] - x_n[i]) / dt;
  state.time_s += dt;
  if (free_dofs_ == 0) {  // no Newton ran: evaluate once at the constrained positions (forces, memory)
    std::vector<double> r;
    residual(state.x, true, x_n, v_n, r);
    if (memory_before_) memory_accepted_.swap(memory_trial_);
  }
  if (memory_before_) {
    state.memory.swap(memory_accepted_);
    state.memory_time_s = state.time_s;
    memory_before_ = nullptr;
  }
  return rep;
}

NewtonReport ImplicitIntegrator::solve_static(State& state) {
  apply_constraints(state, state.time_s);
  update_external(state.time_s);
  NewtonReport rep = free_dofs_ > 0 ? newton(state, false, state.x, state.v) : NewtonReport{0, 0, 0, 0, 0, true, false};
  if (free_dofs_ == 0) {  // every position prescribed: the forces there (last_internal_forces) still
    std::vector<double> r;
    residual(state.x, false, state.x, state.v, r);
  }
  std::fill(state.v.begin(), state.v.end(), Vec3::Zero());
  if (!rep.converged) {
    std::ostringstream msg;
    msg << "static solve did not converge in " << rep.iterations << " Newton iterations: residual " << rep.residual_n << " N";
    throw SimulationError(msg.str());
  }
  return rep;
}

}  // namespace viscera::tissue
