#pragma once  // SPDX-License-Identifier: Apache-2.0
// Independent references for the integrator tests (integrator_test, mass_scaling_test): the dense
// global stiffness of linear FE, its lowest mode and true critical step, the liver fixture.
#include <Eigen/Dense>

#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"

#include "test_support.hpp"

namespace viscera::tissue::integrator_reference {

// Dense global stiffness at rest over all nodes (an independent assembly path).
inline Eigen::MatrixXd dense_stiffness(const TetMesh& mesh, const Mat6& D) {
  const auto n = static_cast<Eigen::Index>(3 * mesh.node_count());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  for (const Tet& t : mesh.tets) {
    const Mat12 Ke = linear_fe_stiffness({mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]}, D);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) K.block<3, 3>(3 * t[a], 3 * t[b]) += Ke.block<3, 3>(3 * a, 3 * b);
  }
  return K;
}

struct Fixture {
  std::shared_ptr<TetMesh> mesh = std::make_shared<TetMesh>(read_tet_mesh(test::data_path("meshes/liver.msh")));
  Fixture() { scale_mesh(*mesh, 0.035); }
  std::vector<double> rho() const { return std::vector<double>(mesh->tet_count(), 1060.0); }
};

/// Lowest natural frequency [rad/s] and its mode (unit mass-norm, over all coordinates, 0 at the
/// fixed nodes) of the dense linear-FE stiffness with lumped masses, fixed nodes removed.
inline std::pair<double, Eigen::VectorXd> lowest_mode(const TetMesh& mesh, const std::vector<double>& masses, const Mat6& D,
                                                      const std::vector<std::int32_t>& fixed_nodes) {
  const Eigen::MatrixXd K = dense_stiffness(mesh, D);
  std::vector<bool> fixed(mesh.node_count(), false);
  for (auto i : fixed_nodes) fixed[static_cast<std::size_t>(i)] = true;
  std::vector<Eigen::Index> free;
  for (Eigen::Index c = 0; c < K.rows(); ++c)
    if (!fixed[static_cast<std::size_t>(c / 3)]) free.push_back(c);
  const auto nf = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd A(nf, nf);
  Eigen::VectorXd s(nf);
  for (Eigen::Index a = 0; a < nf; ++a) s(a) = 1.0 / std::sqrt(masses[static_cast<std::size_t>(free[static_cast<std::size_t>(a)] / 3)]);
  for (Eigen::Index a = 0; a < nf; ++a)
    for (Eigen::Index b = 0; b < nf; ++b) A(a, b) = s(a) * K(free[static_cast<std::size_t>(a)], free[static_cast<std::size_t>(b)]) * s(b);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(K.rows());
  for (Eigen::Index a = 0; a < nf; ++a) u(free[static_cast<std::size_t>(a)]) = s(a) * eig.eigenvectors()(a, 0);
  return {std::sqrt(eig.eigenvalues()(0)), u};
}

/// u^T diag(m) u with lumped masses m per node.
inline double mass_norm2(const Eigen::VectorXd& u, const std::vector<double>& masses) {
  double s = 0;
  for (Eigen::Index c = 0; c < u.size(); ++c) s += masses[static_cast<std::size_t>(c / 3)] * u(c) * u(c);
  return s;
}

inline double true_critical_step(const TetMesh& mesh, const std::vector<double>& masses, const Mat6& D) {
  const Eigen::MatrixXd K = dense_stiffness(mesh, D);
  Eigen::VectorXd inv_sqrt_m(K.rows());
  for (Eigen::Index i = 0; i < K.rows(); ++i) inv_sqrt_m(i) = 1.0 / std::sqrt(masses[static_cast<std::size_t>(i / 3)]);
  const Eigen::MatrixXd A = inv_sqrt_m.asDiagonal() * K * inv_sqrt_m.asDiagonal();
  const double omega2 = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  return 2.0 / std::sqrt(omega2);
}

}  // namespace viscera::tissue::integrator_reference
