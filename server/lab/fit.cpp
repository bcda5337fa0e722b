#include "viscera/lab/fit.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <limits>
#include <mutex>

#include <Eigen/Dense>
#include <malloc.h>

#include "viscera/lab/golden_section.hpp"
#include "viscera/lab/stress_controlled.hpp"

namespace viscera::lab {

Eigen::VectorXd nonnegative_least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const Eigen::Index n = A.cols();
  if (A.rows() > 2 * n) {
    // |A x - b|^2 = |R x - Q^T b|^2 + a constant (A = Q R): the same problem on n rows instead of
    // thousands, so that each of the active-set solves below is small (each used to copy the
    // columns of A, a fresh allocation as large as the data).
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
    const Eigen::MatrixXd R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
    const Eigen::VectorXd c = (qr.householderQ().transpose() * b).head(n);
    return nonnegative_least_squares(R, c);
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(static_cast<std::size_t>(n), false);
  const double tol = 1e-12 * A.norm() * b.norm() + 1e-300;
  for (int outer = 0; outer < 3 * n + 10; ++outer) {
    const Eigen::VectorXd w = A.transpose() * (b - A * x);
    Eigen::Index best = -1;
    double best_w = tol;
    for (Eigen::Index j = 0; j < n; ++j)
      if (!passive[static_cast<std::size_t>(j)] && w(j) > best_w) {
        best_w = w(j);
        best = j;
      }
    if (best < 0) break;
    passive[static_cast<std::size_t>(best)] = true;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      std::vector<Eigen::Index> P;
      for (Eigen::Index j = 0; j < n; ++j)
        if (passive[static_cast<std::size_t>(j)]) P.push_back(j);
      Eigen::MatrixXd Ap(A.rows(), static_cast<Eigen::Index>(P.size()));
      for (std::size_t k = 0; k < P.size(); ++k) Ap.col(static_cast<Eigen::Index>(k)) = A.col(P[k]);
      const Eigen::VectorXd zp = Ap.colPivHouseholderQr().solve(b);
      Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
      for (std::size_t k = 0; k < P.size(); ++k) z(P[k]) = zp(static_cast<Eigen::Index>(k));
      bool feasible = true;
      for (Eigen::Index j : P) feasible = feasible && z(j) > 0;
      if (feasible) {
        x = z;
        break;
      }
      double alpha = 1.0;
      for (Eigen::Index j : P)
        if (z(j) <= 0) alpha = std::min(alpha, x(j) / (x(j) - z(j)));
      x += alpha * (z - x);
      for (Eigen::Index j : P)
        if (x(j) <= 1e-15 * (std::abs(x.maxCoeff()) + 1e-300)) {
          x(j) = 0.0;
          passive[static_cast<std::size_t>(j)] = false;
        }
    }
  }
  return x;
}

namespace {

// The rows of the fit. Strain-controlled tests enter as stress errors, linear in the moduli and
// viscosities for given nonlinear parameters. Stress-controlled tests are fitted on the strain they
// measured (output error; stress_controlled.hpp), in equivalent stress: nonlinear in every
// parameter, so they join in a last Gauss-Newton refinement. The nonlinear search uses the
// strain-controlled tests, or, when a data set has only stress-controlled ones, their equation
// error (the stress the model needs for the measured strain) as a start.
struct Problem {
  std::vector<const TestData*> linear;  // rows linear in the parameters
  std::vector<Eigen::VectorXd> linear_weight;  // per row: 1/sqrt(rows kept), 0 on held-out rows
  std::vector<const TestData*> creep;  // stress-controlled, output error
  std::vector<Eigen::VectorXd> creep_weight;  // the same x apparent modulus
  Eigen::VectorXd b;
};

// Each test weighs equally: its kept rows share a weight 1/sqrt(rows kept); held-out rows get 0.
Eigen::VectorXd row_weights(const TestData* t, const HeldOutRows& held, double scale) {
  const auto n = static_cast<Eigen::Index>(t->time_s.size());
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
  if (held.test == t)
    for (std::size_t k = held.begin; k < held.end && k < t->time_s.size(); ++k) w(static_cast<Eigen::Index>(k)) = 0.0;
  const double kept = w.sum();
  return kept > 0 ? Eigen::VectorXd(w * (scale / std::sqrt(kept))) : w;
}

Eigen::MatrixXd linear_rows(const MaterialModel& m, const Problem& p) {
  Eigen::Index rows = 0;
  for (const TestData* t : p.linear) rows += static_cast<Eigen::Index>(t->time_s.size());
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  Eigen::MatrixXd A(rows, static_cast<Eigen::Index>(2 + L));
  Eigen::Index r = 0;
  for (std::size_t k = 0; k < p.linear.size(); ++k) {
    const Eigen::MatrixXd Bk = basis(m, *p.linear[k]);
    A.block(r, 0, Bk.rows(), Bk.cols()) = p.linear_weight[k].asDiagonal() * Bk;
    r += Bk.rows();
  }
  return A;
}

// Solves the linear part for the given nonlinear parameters; returns the weighted SSE.
// Between platens the model's stress is min(0, A x) (they cannot pull): a row where the model pulls
// costs its measured stress whatever x is, so x is fitted to the rows where it pushes, and the set
// of those rows is found by fixed-point iteration (the best of at most 10 rounds is kept).
double solve_linear(MaterialModel& m, const Problem& p) {
  const Eigen::MatrixXd A = linear_rows(m, p);
  Eigen::VectorXd x = nonnegative_least_squares(A, p.b);
  if (!m.platens) {
    set_linear_coefficients(m, x);
    return (A * x - p.b).squaredNorm();
  }
  const auto cost = [&](const Eigen::VectorXd& c) { return ((A * c).cwiseMin(0.0) - p.b).squaredNorm(); };
  Eigen::VectorXd best = x;
  double best_cost = cost(x);
  Eigen::Array<bool, Eigen::Dynamic, 1> pushes = (A * x).array() <= 0.0;
  for (int round = 0; round < 10; ++round) {
    const Eigen::VectorXd keep = pushes.cast<double>().matrix();
    x = nonnegative_least_squares(keep.asDiagonal() * A, keep.asDiagonal() * p.b);
    if (const double c = cost(x); c < best_cost) {
      best_cost = c;
      best = x;
    }
    const Eigen::Array<bool, Eigen::Dynamic, 1> now = (A * x).array() <= 0.0;
    if ((now == pushes).all()) break;
    pushes = now;
  }
  set_linear_coefficients(m, best);
  return best_cost;
}

// Weighted strain errors of the stress-controlled tests, in equivalent stress.
Eigen::VectorXd creep_residual(const MaterialModel& m, const Problem& p) {
  Eigen::Index rows = 0;
  for (const TestData* t : p.creep) rows += static_cast<Eigen::Index>(t->time_s.size());
  Eigen::VectorXd r(rows);
  Eigen::Index i = 0;
  for (std::size_t k = 0; k < p.creep.size(); ++k) {
    const std::vector<double> e = predict_strain(m, *p.creep[k]);
    for (std::size_t j = 0; j < e.size(); ++j) r(i++) = p.creep_weight[k](static_cast<Eigen::Index>(j)) * (e[j] - p.creep[k]->strain[j]);
  }
  return r;
}

// Gauss-Newton on every test, the linear parameters kept non-negative: each step solves the
// strain-controlled rows and the stress-controlled rows linearised (Jacobian by forward
// differences) as one non-negative least-squares problem, then halves the step until the
// residual falls.
void refine_on_measured(MaterialModel& m, const Problem& p) {
  const Eigen::MatrixXd A = linear_rows(m, p);
  const auto cost = [&](const MaterialModel& x) {
    const Eigen::VectorXd c = creep_residual(x, p);
    return (A.rows() ? (A * linear_coefficients(x) - p.b).squaredNorm() : 0.0) + c.squaredNorm();
  };
  double scale = 0.0;  // a modulus typical of the tests, for the difference steps
  for (const TestData* t : p.creep) scale = std::max(scale, apparent_modulus_pa(*t));
  double current = cost(m);
  for (int it = 0; it < 20; ++it) {
    const Eigen::VectorXd x = linear_coefficients(m), r = creep_residual(m, p);
    Eigen::MatrixXd J(r.size(), x.size());
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      Eigen::VectorXd xs = x;
      const double h = 1e-6 * std::max(std::abs(x(j)), j == 1 ? 1e-2 * scale : scale);
      xs(j) += h;
      MaterialModel ms = m;
      set_linear_coefficients(ms, xs);
      J.col(j) = (creep_residual(ms, p) - r) / h;
    }
    Eigen::MatrixXd M(A.rows() + J.rows(), x.size());
    Eigen::VectorXd rhs(M.rows());
    M << A, J;
    rhs << p.b, J * x - r;
    const Eigen::VectorXd step = nonnegative_least_squares(M, rhs) - x;
    bool improved = false;
    for (double f = 1.0; f > 1e-3; f *= 0.5) {
      MaterialModel trial = m;
      set_linear_coefficients(trial, (x + f * step).cwiseMax(0.0));
      const double c = cost(trial);
      if (c < current) {
        improved = current - c > 1e-10 * current;
        m = trial;
        current = c;
        break;
      }
    }
    if (!improved) break;
  }
}

struct Nonlinear {
  double* value;
  double lo, hi;
  bool log_scale;
};

// Grid then golden-section refinement of one nonlinear parameter, others held.
void search(MaterialModel& m, const Problem& p, const Nonlinear& q) {
  const int grid = 17;
  const auto at = [&](double u) { return q.log_scale ? std::exp(u) : u; };
  const double ulo = q.log_scale ? std::log(q.lo) : q.lo, uhi = q.log_scale ? std::log(q.hi) : q.hi;
  double best_u = ulo, best = std::numeric_limits<double>::infinity();
  for (int g = 0; g < grid; ++g) {
    const double u = ulo + (uhi - ulo) * g / (grid - 1);
    *q.value = at(u);
    const double c = solve_linear(m, p);
    if (c < best) {
      best = c;
      best_u = u;
    }
  }
  const double a = std::max(ulo, best_u - (uhi - ulo) / (grid - 1)), b = std::min(uhi, best_u + (uhi - ulo) / (grid - 1));
  const Minimum refined = golden_section(
      [&](double u) {
        *q.value = at(u);
        return solve_linear(m, p);
      },
      a, b, 0.0, 30);
  *q.value = at(refined.f > best ? best_u : refined.x);
  solve_linear(m, p);
}

}  // namespace

MaterialModel fit_model(const MaterialModel& structure, const std::vector<const TestData*>& tests, const HeldOutRows& held) {
  // The fits build and drop matrices of a few hundred kB many thousand times, on several threads.
  // glibc hands such blocks back to the kernel on every free (mmap, and madvise on a thread's
  // arena) and faults them in again: on the rough-discs analysis that was 20 of 43 s, all of it in
  // the kernel. Keeping up to 256 MiB of freed memory in the process made it 26 s.
  static std::once_flag keep_freed_memory;
  std::call_once(keep_freed_memory, [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
  });
  Problem p;
  for (const TestData* t : tests) (t->control == Control::strain ? p.linear : p.creep).push_back(t);
  const bool output_error = !p.creep.empty();
  if (p.linear.empty()) std::swap(p.linear, p.creep);  // only stress control: equation error to start
  Eigen::Index rows = 0;
  for (const TestData* t : p.linear) rows += static_cast<Eigen::Index>(t->time_s.size());
  p.b.resize(rows);
  Eigen::Index r = 0;
  for (const TestData* t : p.linear) {
    p.linear_weight.push_back(row_weights(t, held, 1.0));
    for (std::size_t j = 0; j < t->stress_pa.size(); ++j) p.b(r++) = p.linear_weight.back()(static_cast<Eigen::Index>(j)) * t->stress_pa[j];
  }
  MaterialModel m = structure;
  m.stiffening_b = 0.0;
  m.compression_ratio = 1.0;
  m.softening_d = 0.0;
  m.softening_kept = 1.0;
  m.contact_strain = 0.0;
  std::vector<Nonlinear> params;
  if (m.has(Mechanism::strain_stiffening)) params.push_back({&m.stiffening_b, 0.05, 200.0, true});
  if (m.has(Mechanism::tension_compression_asymmetry)) params.push_back({&m.compression_ratio, 0.05, 20.0, true});
  if (m.has(Mechanism::first_load_softening)) params.push_back({&m.softening_d, 0.0, 0.95, false});
  if (m.has(Mechanism::first_load_softening) && m.history_carried) params.push_back({&m.softening_kept, 0.0, 1.0, false});
  // A gap of up to a third of the specimen's height (contact taken up over the first 30%).
  if (m.has(Mechanism::contact_take_up)) params.push_back({&m.contact_strain, 0.0, 0.3, false});
  if (params.empty()) {
    solve_linear(m, p);
  } else {
    // Stiffening's form is a discrete parameter: the search runs for each allowed form and the
    // best fit is kept.
    std::vector<StiffeningForm> forms{m.stiffening_form};
    if (m.has(Mechanism::strain_stiffening)) {
      forms = {StiffeningForm::odd_exponential, StiffeningForm::odd_polynomial, StiffeningForm::ogden};
      if (!m.odd_only) forms.insert(forms.begin(), StiffeningForm::exponential);
    }
    MaterialModel best;
    double best_cost = std::numeric_limits<double>::infinity();
    for (StiffeningForm form : forms) {
      m.stiffening_form = form;
      m.stiffening_b = 0.0;
      m.compression_ratio = 1.0;
      m.softening_d = 0.0;
      m.softening_kept = 1.0;
      m.contact_strain = 0.0;
      for (int round = 0; round < (params.size() > 1 ? 3 : 1); ++round)
        for (const auto& q : params) search(m, p, q);
      const double cost = solve_linear(m, p);
      if (cost < best_cost) {
        best_cost = cost;
        best = m;
      }
    }
    m = best;
  }
  if (output_error) {
    if (p.creep.empty()) {  // the start came from the equation error: now fit what was measured
      std::swap(p.linear, p.creep);
      p.linear_weight.clear();
      p.b.resize(0);
    }
    for (const TestData* t : p.creep) p.creep_weight.push_back(row_weights(t, held, apparent_modulus_pa(*t)));
    refine_on_measured(m, p);
  }
  return m;
}

double rms_error_measured(const MaterialModel& m, const TestData& t) {
  const auto y = predict_measured(m, t);
  const std::vector<double>& measured = t.control == Control::strain ? t.stress_pa : t.strain;
  double s = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) s += (y[k] - measured[k]) * (y[k] - measured[k]);
  return std::sqrt(s / static_cast<double>(y.size()));
}

double rms_error_pa(const MaterialModel& m, const TestData& t) {
  return rms_error_measured(m, t) * (t.control == Control::strain ? 1.0 : apparent_modulus_pa(t));
}

}  // namespace viscera::lab
