#include "viscera/lab/fit.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "viscera/lab/golden_section.hpp"

namespace viscera::lab {

Eigen::VectorXd nonnegative_least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const Eigen::Index n = A.cols();
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

struct Problem {
  const std::vector<const TestData*>& tests;
  Eigen::VectorXd b;
  std::vector<double> weight;  // per test
};

// Solves the linear part for the given nonlinear parameters; returns the weighted SSE.
double solve_linear(MaterialModel& m, const Problem& p) {
  Eigen::Index rows = 0;
  for (const TestData* t : p.tests) rows += static_cast<Eigen::Index>(t->time_s.size());
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  Eigen::MatrixXd A(rows, static_cast<Eigen::Index>(2 + L));
  Eigen::Index r = 0;
  for (std::size_t k = 0; k < p.tests.size(); ++k) {
    const Eigen::MatrixXd Bk = basis(m, *p.tests[k]);
    A.block(r, 0, Bk.rows(), Bk.cols()) = p.weight[k] * Bk;
    r += Bk.rows();
  }
  const Eigen::VectorXd x = nonnegative_least_squares(A, p.b);
  m.modulus_pa = x(0);
  m.viscosity_pa_s = x(1);
  m.relaxation_modulus_pa.assign(L, 0.0);
  for (std::size_t l = 0; l < L; ++l) m.relaxation_modulus_pa[l] = x(static_cast<Eigen::Index>(2 + l));
  return (A * x - p.b).squaredNorm();
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

MaterialModel fit_model(const MaterialModel& structure, const std::vector<const TestData*>& tests) {
  Problem p{tests, {}, {}};
  Eigen::Index rows = 0;
  for (const TestData* t : tests) rows += static_cast<Eigen::Index>(t->time_s.size());
  p.b.resize(rows);
  Eigen::Index r = 0;
  for (const TestData* t : tests) {
    const double w = 1.0 / std::sqrt(static_cast<double>(t->time_s.size()));
    p.weight.push_back(w);
    for (double s : t->stress_pa) p.b(r++) = w * s;
  }
  MaterialModel m = structure;
  m.stiffening_b = 0.0;
  m.compression_ratio = 1.0;
  m.softening_d = 0.0;
  std::vector<Nonlinear> params;
  if (m.has(Mechanism::strain_stiffening)) params.push_back({&m.stiffening_b, 0.05, 200.0, true});
  if (m.has(Mechanism::tension_compression_asymmetry)) params.push_back({&m.compression_ratio, 0.05, 20.0, true});
  if (m.has(Mechanism::first_load_softening)) params.push_back({&m.softening_d, 0.0, 0.95, false});
  if (params.empty()) {
    solve_linear(m, p);
    return m;
  }
  for (int round = 0; round < (params.size() > 1 ? 3 : 1); ++round)
    for (const auto& q : params) search(m, p, q);
  return m;
}

double rms_error_pa(const MaterialModel& m, const TestData& t) {
  const auto y = predict_stress(m, t);
  double s = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) s += (y[k] - t.stress_pa[k]) * (y[k] - t.stress_pa[k]);
  return std::sqrt(s / static_cast<double>(y.size()));
}

}  // namespace viscera::lab
