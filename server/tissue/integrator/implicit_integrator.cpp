#include "integrator/implicit_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/input_error.hpp"

namespace viscera::tissue {

namespace {
double norm(const std::vector<double>& r) {
  double s = 0.0;
  for (double v : r) s += v * v;
  return std::sqrt(s);
}
}  // namespace

ImplicitIntegrator::ImplicitIntegrator(const ForceModel& model, std::vector<double> density_kg_m3,
                                       BoundaryConditions bc, ImplicitOptions options)
    : model_(model), bc_(std::move(bc)), options_(options) {
  if (!(options_.dt_s > 0)) throw std::invalid_argument("ImplicitOptions.dt_s must be > 0");
  mass_ = lumped_masses(model.rest_mesh(), density_kg_m3);
  const std::size_t n = mass_.size();
  external_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    external_[i] = mass_[i] * bc_.gravity_m_s2;
    if (!bc_.nodal_forces.empty()) external_[i] += bc_.nodal_forces.at(i);
  }
  const auto mask = bc_.constrained_mask(n);
  dof_.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (!mask[i]) {
      dof_[i] = free_dofs_;
      free_dofs_ += 3;
    }
  force_.resize(n);
  if (free_dofs_ == 0) return;

  // Sparsity pattern of the upper triangle over free dofs: 3x3 blocks between nodes of a tet.
  std::vector<std::vector<int>> rows(static_cast<std::size_t>(free_dofs_));
  for (std::size_t e = 0; e < model.element_count(); ++e) {
    const Tet& t = model.element(e);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        const int da = dof_[t[a]], db = dof_[t[b]];
        if (da < 0 || db < 0) continue;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (da + i <= db + j) rows[static_cast<std::size_t>(db + j)].push_back(da + i);
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
  element_slots_.assign(144 * model.element_count(), -1);
  for (std::size_t e = 0; e < model.element_count(); ++e) {
    const Tet& t = model.element(e);
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q) {
        const int dp = dof_[t[p / 3]], dq = dof_[t[q / 3]];
        if (dp < 0 || dq < 0) continue;
        const int r = dp + p % 3, c = dq + q % 3;
        if (r <= c) element_slots_[144 * e + 12 * p + q] = solver_->slot(r, c);
      }
  }
  diagonal_slots_.resize(static_cast<std::size_t>(free_dofs_));
  for (int d = 0; d < free_dofs_; ++d) diagonal_slots_[static_cast<std::size_t>(d)] = solver_->slot(d, d);
}

ImplicitIntegrator::~ImplicitIntegrator() = default;

void ImplicitIntegrator::apply_constraints(State& state, double t) {
  const auto& rest = model_.rest_mesh().nodes;
  for (auto i : bc_.fixed_nodes) state.x[i] = rest[i];
  for (const auto& p : bc_.prescribed)
    for (auto i : p.nodes) state.x[i] = p.position(rest[i], t);
}

double ImplicitIntegrator::residual(const std::vector<Vec3>& x, bool dynamic, const std::vector<Vec3>& x_n,
                                    const std::vector<Vec3>& v_n, std::vector<double>& r) {
  std::fill(force_.begin(), force_.end(), Vec3::Zero());
  model_.add_forces(x, force_);
  const double dt = options_.dt_s;
  const double mass_scale = (1.0 + options_.mass_damping_per_s * dt) / (dt * dt);
  r.assign(static_cast<std::size_t>(free_dofs_), 0.0);
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    if (dof_[i] < 0) continue;
    Vec3 ri = -force_[i] - external_[i];
    if (dynamic) ri += mass_[i] * (mass_scale * (x[i] - x_n[i]) - v_n[i] / dt);
    for (int k = 0; k < 3; ++k) r[static_cast<std::size_t>(dof_[i] + k)] = ri[k];
  }
  return norm(r);
}

void ImplicitIntegrator::assemble(const std::vector<Vec3>& x, double mass_scale, double regularisation) {
  std::span<double> values = solver_->values();
  std::fill(values.begin(), values.end(), 0.0);
  for (std::size_t e = 0; e < model_.element_count(); ++e) {
    const Mat12 K = model_.element_tangent(x, e);
    const long* slots = &element_slots_[144 * e];
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q)
        if (slots[12 * p + q] >= 0) values[static_cast<std::size_t>(slots[12 * p + q])] += 0.5 * (K(p, q) + K(q, p));
  }
  double mean_diagonal = 0.0;
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    if (dof_[i] < 0) continue;
    for (int k = 0; k < 3; ++k)
      values[static_cast<std::size_t>(diagonal_slots_[static_cast<std::size_t>(dof_[i] + k)])] += mass_scale * mass_[i];
  }
  if (regularisation > 0) {
    for (long s : diagonal_slots_) mean_diagonal += values[static_cast<std::size_t>(s)];
    mean_diagonal /= static_cast<double>(diagonal_slots_.size());
    for (long s : diagonal_slots_) values[static_cast<std::size_t>(s)] += regularisation * mean_diagonal;
  }
}

NewtonReport ImplicitIntegrator::newton(State& state, bool dynamic, const std::vector<Vec3>& x_n,
                                        const std::vector<Vec3>& v_n) {
  NewtonReport rep;
  std::vector<double> r, dx(static_cast<std::size_t>(free_dofs_));
  double rn = residual(state.x, dynamic, x_n, v_n, r);
  rep.initial_residual_n = rn;
  double ext = 0.0;
  for (std::size_t i = 0; i < mass_.size(); ++i)
    if (dof_[i] >= 0) ext += external_[i].squaredNorm();
  rep.force_scale_n = std::max(rn, std::sqrt(ext));
  const double dt = options_.dt_s;
  const double mass_scale = dynamic ? (1.0 + options_.mass_damping_per_s * dt) / (dt * dt) : 0.0;
  std::vector<Vec3> trial;
  const auto converged = [&] { return rn <= options_.relative_tolerance * rep.force_scale_n; };
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
      for (std::size_t i = 0; i < mass_.size(); ++i)
        if (dof_[i] >= 0)
          for (int k = 0; k < 3; ++k) trial[i][k] -= alpha * dx[static_cast<std::size_t>(dof_[i] + k)];
      std::vector<double> r_trial;
      const double rt = residual(trial, dynamic, x_n, v_n, r_trial);
      if (rt < rn || ls == 11) {
        state.x.swap(trial);
        r.swap(r_trial);
        rn = rt;
        break;
      }
    }
    // Round-off floor: a full Newton step that no longer halves an already tiny residual.
    if (!converged() && rn > 0.5 * rn_before && rn <= 1e-6 * rep.force_scale_n) {
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
  for (std::size_t i = 0; i < mass_.size(); ++i) state.x[i] += dt * state.v[i];  // predictor
  apply_constraints(state, state.time_s + dt);
  NewtonReport rep = free_dofs_ > 0 ? newton(state, true, x_n, v_n) : NewtonReport{0, 0, 0, 0, 0, true, false};
  if (!rep.converged) {
    std::ostringstream msg;
    msg << "implicit step at t = " << state.time_s << " s did not converge in " << rep.iterations
        << " Newton iterations: residual " << rep.residual_n << " N (tolerance "
        << options_.relative_tolerance * rep.force_scale_n << " N)";
    state.x = x_n;
    state.v = v_n;
    throw SimulationError(msg.str());
  }
  for (std::size_t i = 0; i < mass_.size(); ++i) state.v[i] = (state.x[i] - x_n[i]) / dt;
  state.time_s += dt;
  return rep;
}

NewtonReport ImplicitIntegrator::solve_static(State& state) {
  apply_constraints(state, state.time_s);
  NewtonReport rep = free_dofs_ > 0 ? newton(state, false, state.x, state.v) : NewtonReport{0, 0, 0, 0, 0, true, false};
  std::fill(state.v.begin(), state.v.end(), Vec3::Zero());
  if (!rep.converged) {
    std::ostringstream msg;
    msg << "static solve did not converge in " << rep.iterations << " Newton iterations: residual "
        << rep.residual_n << " N";
    throw SimulationError(msg.str());
  }
  return rep;
}

}  // namespace viscera::tissue
