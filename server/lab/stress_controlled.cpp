#include "viscera/lab/stress_controlled.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "viscera/lab/command_path.hpp"

namespace viscera::lab {

namespace {

// Integrals over one interval of length dt of exp(lambda (dt - u)) and of u exp(lambda (dt - u)).
void phi(double lambda, double dt, double* phi1, double* phi2) {
  const double x = lambda * dt;
  if (std::abs(x) < 1e-5) {
    *phi1 = dt * (1 + x / 2 + x * x / 6);
    *phi2 = dt * dt * (0.5 + x / 6 + x * x / 24);
    return;
  }
  const double em1 = std::expm1(x);
  *phi1 = em1 / lambda;
  *phi2 = (em1 - x) / (lambda * lambda);
}

}  // namespace

std::vector<double> predict_strain(const MaterialModel& m, const TestData& t) {
  // The state keeps only the relaxation terms with a modulus: the others never act on s.
  std::vector<double> w{m.modulus_pa}, inv_tau{0.0};
  if (m.has(Mechanism::broadband_relaxation))
    for (std::size_t l = 0; l < m.relaxation_time_s.size(); ++l)
      if (m.relaxation_modulus_pa[l] > 0) {
        w.push_back(m.relaxation_modulus_pa[l]);
        inv_tau.push_back(1.0 / m.relaxation_time_s[l]);
      }
  double total = 0.0;
  for (double x : w) total += x;
  // A zero modulus would make the similarity transform singular: a millionth of the total is
  // below anything a test resolves. A vanishing viscosity is a very fast mode, which the exact
  // integration takes as instantaneous.
  for (double& x : w) x = std::max(x, 1e-6 * total + 1e-300);
  total = 0.0;
  for (double x : w) total += x;
  const double eta = std::max(m.viscosity_pa_s, 1e-12 * total);
  const auto n = static_cast<Eigen::Index>(w.size());
  Eigen::VectorXd q(n);
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    q(i) = std::sqrt(w[static_cast<std::size_t>(i)]);
    S(i, i) = -inv_tau[static_cast<std::size_t>(i)];
  }
  S -= q * q.transpose() / eta;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const Eigen::MatrixXd& Q = eig.eigenvectors();
  // Modal coordinates y = Q^T W^(1/2) x; input c = Q^T q / eta; s = x_0 = (Q y)_0 / sqrt(w_0).
  const Eigen::VectorXd c = Q.transpose() * q / eta;
  const Eigen::RowVectorXd s_of_y = Q.row(0) / q(0);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  const CommandPath path = command_path(t.time_s, t.stress_pa);
  std::vector<double> strain;
  strain.reserve(t.time_s.size());
  ElasticShape shape = shape_at_start(m, t);
  std::size_t next = 0;
  for (std::size_t j = 0; j < path.time_s.size(); ++j) {
    if (j > 0) {
      const double dt = path.time_s[j] - path.time_s[j - 1], s0 = path.value[j - 1], slope = (path.value[j] - s0) / dt;
      for (Eigen::Index i = 0; i < n; ++i) {
        double p1, p2;
        phi(lambda(i), dt, &p1, &p2);
        y(i) = std::exp(lambda(i) * dt) * y(i) + c(i) * (s0 * p1 + slope * p2);
      }
    }
    if (path.sample[next] != j) continue;
    ++next;
    const double e = shape.strain_for(s_of_y * y);
    shape.advance(e);
    strain.push_back(e);
  }
  return strain;
}

double apparent_modulus_pa(const TestData& t) {
  double s = 0.0, e = 0.0;
  for (std::size_t k = 0; k < t.time_s.size(); ++k) {
    s = std::max(s, std::abs(t.stress_pa[k]));
    e = std::max(e, std::abs(t.strain[k]));
  }
  return e > 0 ? s / e : 0.0;
}

std::vector<double> predict_measured(const MaterialModel& m, const TestData& t) {
  return t.control == Control::strain ? predict_stress(m, t) : predict_strain(m, t);
}

}  // namespace viscera::lab
