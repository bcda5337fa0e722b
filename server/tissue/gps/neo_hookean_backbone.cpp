#include "viscera/tissue/gps/neo_hookean_backbone.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::tissue {

namespace {

Mat3 deformation_gradient(const std::array<Vec3, 4>& x, const Mat3& dm_inv) {
  Mat3 ds;
  for (int c = 0; c < 3; ++c) ds.col(c) = x[c + 1] - x[0];
  return ds * dm_inv;
}

/// cof(F) = J F^-T, column by column, defined for every F.
Mat3 cofactor(const Mat3& F) {
  Mat3 c;
  c.col(0) = F.col(1).cross(F.col(2));
  c.col(1) = F.col(2).cross(F.col(0));
  c.col(2) = F.col(0).cross(F.col(1));
  return c;
}

/// d cof(F) along dF.
Mat3 cofactor_derivative(const Mat3& F, const Mat3& dF) {
  Mat3 d;
  d.col(0) = dF.col(1).cross(F.col(2)) + F.col(1).cross(dF.col(2));
  d.col(1) = dF.col(2).cross(F.col(0)) + F.col(2).cross(dF.col(0));
  d.col(2) = dF.col(0).cross(F.col(1)) + F.col(0).cross(dF.col(1));
  return d;
}

/// The rows g_v with F = sum_v x_v g_v^T: Dm^-1's rows for vertices 1-3, minus their sum for 0.
Eigen::Matrix<double, 4, 3> vertex_gradients(const Mat3& dm_inv) {
  Eigen::Matrix<double, 4, 3> g;
  g.block<3, 3>(1, 0) = dm_inv;
  g.row(0) = -(dm_inv.row(0) + dm_inv.row(1) + dm_inv.row(2));
  return g;
}

/// Vertex forces of a first Piola-Kirchhoff stress: -V0 P Dm^-T on vertices 1-3, their negative sum on 0.
Vec12 forces_of(const Mat3& P, const Mat3& dm_inv, double V0) {
  const Mat3 h = -V0 * P * dm_inv.transpose();
  Vec12 f;
  f.segment<3>(3) = h.col(0);
  f.segment<3>(6) = h.col(1);
  f.segment<3>(9) = h.col(2);
  f.segment<3>(0) = -(h.col(0) + h.col(1) + h.col(2));
  return f;
}

}  // namespace

NeoHookean neo_hookean_of(const Mat6& D) {
  const double mu = D(3, 3), lambda = D(0, 1);
  const double scale = D.cwiseAbs().maxCoeff();
  const auto near = [&](double a, double b) { return std::abs(a - b) <= 1e-9 * scale; };
  for (int i = 0; i < 3; ++i) {
    if (!near(D(i, i), lambda + 2 * mu) || !near(D(i + 3, i + 3), mu))
      throw std::invalid_argument("the large-strain GPS needs an isotropic material (its neo-Hookean backbone)");
    for (int j = 0; j < 3; ++j)
      if (i != j && !near(D(i, j), lambda))
        throw std::invalid_argument("the large-strain GPS needs an isotropic material (its neo-Hookean backbone)");
  }
  if (!(mu > 0 && lambda + mu > 0)) throw std::invalid_argument("the large-strain GPS needs positive shear and lambda + mu");
  return {mu, lambda + mu};
}

Mat3 rest_shape_inverse(const std::array<Vec3, 4>& rest) {
  Mat3 dm;
  for (int c = 0; c < 3; ++c) dm.col(c) = rest[c + 1] - rest[0];
  return dm.inverse();
}

double neo_hookean_energy(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0) {
  const Mat3 F = deformation_gradient(x, dm_inv);
  const double J = F.determinant(), a = m.alpha();
  return V0 * (0.5 * m.mu * (F.squaredNorm() - 3.0) + 0.5 * m.lam * ((J - a) * (J - a) - (1.0 - a) * (1.0 - a)));
}

Vec12 neo_hookean_forces(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0) {
  const Mat3 F = deformation_gradient(x, dm_inv);
  const Mat3 P = m.mu * F + m.lam * (F.determinant() - m.alpha()) * cofactor(F);
  return forces_of(P, dm_inv, V0);
}

Mat12 neo_hookean_tangent(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0) {
  // Column by column: the directional derivative of the forces along each coordinate of each vertex.
  const Mat3 F = deformation_gradient(x, dm_inv), C = cofactor(F);
  const double s = F.determinant() - m.alpha();
  // dF for a unit move of vertex v along axis d: e_d (row of Dm^-1 of v - 1), or minus their sum for v = 0.
  const Eigen::Matrix<double, 4, 3> grad = vertex_gradients(dm_inv);  // dF = e_d grad.row(v)
  Mat12 K;
  for (int v = 0; v < 4; ++v)
    for (int d = 0; d < 3; ++d) {
      const Mat3 dF = Vec3::Unit(d) * grad.row(v);
      const Mat3 dC = cofactor_derivative(F, dF);
      const double dJ = (C.array() * dF.array()).sum();
      const Mat3 dP = m.mu * dF + m.lam * (dJ * C + s * dC);
      K.col(3 * v + d) = -forces_of(dP, dm_inv, V0);
    }
  return 0.5 * (K + K.transpose());
}

Mat12 deviatoric_stress_tangent(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0) {
  // T = mu (F - tr(C) cof / (3 Jf)); f_w = -V0 T g_w, so column (v, d) is V0 dT g_w.
  const Mat3 F = deformation_gradient(x, dm_inv), C = cofactor(F);
  const double J = F.determinant(), Jf = std::max(J, kBackboneMemoryFloorJ), trC = F.squaredNorm();
  const Eigen::Matrix<double, 4, 3> grad = vertex_gradients(dm_inv);
  Mat12 K;
  for (int v = 0; v < 4; ++v)
    for (int d = 0; d < 3; ++d) {
      const Mat3 dF = Vec3::Unit(d) * grad.row(v);
      const Mat3 dC = cofactor_derivative(F, dF);
      const double dtrC = 2.0 * (F.array() * dF.array()).sum();
      // d(cof / Jf): dcof / Jf - cof dJ / J^2 above the floor, dcof / Jf below it.
      Mat3 dcof_j = dC / Jf;
      if (J >= kBackboneMemoryFloorJ) dcof_j -= C * ((C.array() * dF.array()).sum() / (J * J));
      const Mat3 dT = m.mu * (dF - (dtrC / (3 * Jf)) * C - (trC / 3) * dcof_j);
      for (int w = 0; w < 4; ++w) K.block<3, 1>(3 * w, 3 * v + d) = V0 * dT * grad.row(w).transpose();
    }
  return K;
}

Mat12 held_stress_tangent(const Mat3& held, const Mat3& dm_inv, double V0) {
  const Eigen::Matrix<double, 4, 3> grad = vertex_gradients(dm_inv);  // F = sum_v x_v grad.row(v)
  Mat12 K = Mat12::Zero();
  for (int v = 0; v < 4; ++v)
    for (int w = 0; w < 4; ++w) K.block<3, 3>(3 * w, 3 * v) = (-V0 * grad.row(v).dot(held * grad.row(w).transpose())) * Mat3::Identity();
  return K;
}

}  // namespace viscera::tissue
