#include "viscera/tissue/integrator/stable_step.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace viscera::tissue {

namespace {

/// Element e's rest positions, symmetrised tangent at rest and lumped mass per vertex [kg].
struct RestElement {
  std::array<Vec3, 4> x;
  Mat12 K;
  double mass = 0;
};
RestElement rest_element(const ForceModel& model, std::size_t e, double density_kg_m3) {
  RestElement r{model.gather(model.rest_mesh().nodes, e), model.element_tangent(model.rest_mesh().nodes, e), 0.0};
  r.K = 0.5 * (r.K + r.K.transpose());
  r.mass = 0.25 * density_kg_m3 * signed_volume(r.x[0], r.x[1], r.x[2], r.x[3]);
  return r;
}

/// The largest eigenvalue of K. At rest, stress free, a tetrahedron's tangent vanishes on its six
/// rigid motions, which are the null space of its edge-elongation map J (6x12, rank 6): K = J^T M J
/// with M = J+^T K J+, and its nonzero eigenvalues are those of L^-1 (J K J^T) L^-T, L L^T = J J^T,
/// a 6x6 problem (a third of the 12x12 one's cost). A tetrahedron too flat for the Cholesky factor
/// falls back on the 12x12 problem.
double largest_eigenvalue(const RestElement& r) {
  const Mat6x12 J = elongation_jacobian(r.x);
  const Eigen::LLT<Mat6> llt(J * J.transpose());
  if (llt.info() == Eigen::Success) {
    Mat6 A = J * r.K * J.transpose();
    llt.matrixL().solveInPlace(A);  // L^-1 P
    const Mat6 B = A.transpose();
    Mat6 C = B;
    llt.matrixL().solveInPlace(C);  // L^-1 (L^-1 P)^T = L^-1 P^T L^-T = L^-1 P L^-T (P symmetric)
    const Mat6 S = 0.5 * (C + C.transpose());
    return Eigen::SelfAdjointEigenSolver<Mat6>(S, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  }
  return Eigen::SelfAdjointEigenSolver<Mat12>(r.K, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

}  // namespace

double element_frequency(const ForceModel& model, std::size_t e, double density_kg_m3) {
  const RestElement r = rest_element(model, e, density_kg_m3);
  return std::sqrt(largest_eigenvalue(r) / r.mass);
}

double element_frequency_above(const ForceModel& model, std::size_t e, double density_kg_m3, double omega_rad_s) {
  const RestElement r = rest_element(model, e, density_kg_m3);
  // K is positive semi-definite at rest: its largest eigenvalue is at most its trace and at most
  // its largest absolute row sum (Gershgorin).
  const double bound = std::min(r.K.trace(), r.K.cwiseAbs().rowwise().sum().maxCoeff());
  if (bound <= omega_rad_s * omega_rad_s * r.mass) return std::sqrt(bound / r.mass);
  return std::sqrt(largest_eigenvalue(r) / r.mass);
}

std::vector<double> element_frequencies(const ForceModel& model, std::span<const double> density_kg_m3) {
  if (density_kg_m3.size() != model.element_count()) throw std::invalid_argument("element_frequencies: one density per element expected");
  std::vector<double> omega(model.element_count());
  for (std::size_t e = 0; e < model.element_count(); ++e) omega[e] = element_frequency(model, e, density_kg_m3[e]);
  return omega;
}

StableStep critical_time_step(const ForceModel& model, std::span<const double> density_kg_m3) {
  const std::vector<double> omegas = element_frequencies(model, density_kg_m3);
  if (omegas.empty()) throw std::invalid_argument("critical_time_step: the model has no elements");
  const auto worst = std::max_element(omegas.begin(), omegas.end());
  const double omega = *worst;
  // Stiffness-proportional damping (Kelvin-Voigt, time tau) shortens the step of central
  // differences to (2 / omega) (sqrt(1 + xi^2) - xi), xi = tau omega / 2 (Belytschko et al.).
  const double xi = 0.5 * model.stiffness_damping_time_s() * omega;
  return {2.0 / omega * (std::sqrt(1.0 + xi * xi) - xi), omega, static_cast<std::size_t>(worst - omegas.begin())};
}

StableStep global_time_step(const ForceModel& model, std::span<const double> masses, std::span<const char> constrained, int iterations,
                            double margin) {
  const auto& X = model.rest_mesh().nodes;
  const std::size_t n = X.size();
  std::vector<double> inv_sqrt_m(n);
  for (std::size_t i = 0; i < n; ++i) inv_sqrt_m[i] = 1.0 / std::sqrt(masses[i]);
  double h = 0.0;  // mean edge length: sets the finite-difference step
  for (std::size_t e = 0; e < model.element_count(); ++e) {
    const auto p = model.gather(X, e);
    h += (p[1] - p[0]).norm();
  }
  h /= static_cast<double>(model.element_count());
  std::vector<Vec3> v(n), xp(n), xm(n), fp(n), fm(n), w(n);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;  // deterministic start vector
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      v[i][k] = constrained[3 * i + k] ? 0.0 : static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
    }
  const auto normalize = [&](std::vector<Vec3>& a) {
    double s = 0;
    for (const auto& x : a) s += x.squaredNorm();
    s = std::sqrt(s);
    for (auto& x : a) x /= s;
  };
  normalize(v);
  double lambda = 0.0;
  for (int it = 0; it < iterations; ++it) {
    // w = M^-1/2 K M^-1/2 v, with K u = -(f(X + eps u) - f(X - eps u)) / (2 eps).
    double umax = 0;
    for (std::size_t i = 0; i < n; ++i) umax = std::max(umax, (inv_sqrt_m[i] * v[i]).cwiseAbs().maxCoeff());
    const double eps = 1e-6 * h / umax;
    for (std::size_t i = 0; i < n; ++i) {
      xp[i] = X[i] + eps * inv_sqrt_m[i] * v[i];
      xm[i] = X[i] - eps * inv_sqrt_m[i] * v[i];
    }
    std::fill(fp.begin(), fp.end(), Vec3::Zero());
    std::fill(fm.begin(), fm.end(), Vec3::Zero());
    model.add_forces(xp, fp);
    model.add_forces(xm, fm);
    double rq = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      w[i] = -(fp[i] - fm[i]) / (2 * eps) * inv_sqrt_m[i];
      for (int k = 0; k < 3; ++k)
        if (constrained[3 * i + k]) w[i][k] = 0.0;
      rq += w[i].dot(v[i]);
    }
    lambda = rq;  // Rayleigh quotient with |v| = 1
    v = w;
    normalize(v);
  }
  const double omega = std::sqrt(margin * lambda);
  const double xi = 0.5 * model.stiffness_damping_time_s() * omega;
  return {2.0 / omega * (std::sqrt(1.0 + xi * xi) - xi), omega, 0};
}

}  // namespace viscera::tissue
