#pragma once  // SPDX-License-Identifier: Apache-2.0
// Geometry of one linear tetrahedron: volume, shape-function gradients, the linear FE
// strain-displacement matrix and the edge-elongation Jacobian of docs/MODEL.md section 1.
//
// Conventions used everywhere in the core:
//  - vertex order 0..3 with signed volume ((x1-x0) x (x2-x0)) . (x3-x0) / 6 > 0;
//  - edges in the fixed order (0,1) (0,2) (0,3) (1,2) (1,3) (2,3), edge e = (a,b),
//    edge vector Y_e = x_b - x_a;
//  - Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains (gamma = 2 eps).
#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace viscera::tissue {

using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Mat6x12 = Eigen::Matrix<double, 6, 12>;

inline constexpr std::array<std::array<int, 2>, 6> kTetEdges{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

inline double signed_volume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2, const Eigen::Vector3d& x3) {
  return (x1 - x0).cross(x2 - x0).dot(x3 - x0) / 6.0;
}

/// Edge matrix Dm = [x1-x0, x2-x0, x3-x0].
inline Mat3 edge_matrix(const std::array<Eigen::Vector3d, 4>& x) {
  Mat3 d;
  d.col(0) = x[1] - x[0];
  d.col(1) = x[2] - x[0];
  d.col(2) = x[3] - x[0];
  return d;
}

/// Gradients of the four linear shape functions (rows of the returned 4x3), given Dm^-1.
inline Eigen::Matrix<double, 4, 3> shape_gradients(const Mat3& dm_inv) {
  Eigen::Matrix<double, 4, 3> g;
  g.row(1) = dm_inv.row(0);
  g.row(2) = dm_inv.row(1);
  g.row(3) = dm_inv.row(2);
  g.row(0) = -(g.row(1) + g.row(2) + g.row(3));
  return g;
}

/// Linear FE strain-displacement matrix B (6x12): Voigt strain = B u.
Mat6x12 strain_displacement(const Mat3& dm_inv);

/// Linear FE element stiffness K = V B^T D B (12x12) for rest positions x and elasticity D.
Mat12 linear_fe_stiffness(const std::array<Eigen::Vector3d, 4>& x, const Mat6& D);

/// Edge-elongation Jacobian J (6x12): dL = J u for small u. Row e holds -n_e at vertex a and
/// +n_e at vertex b, n_e = Y_e / |Y_e| (docs/MODEL.md section 1).
Mat6x12 elongation_jacobian(const std::array<Eigen::Vector3d, 4>& x);

/// Gradient of the signed volume with respect to the 12 vertex coordinates.
Vec12 volume_gradient(const std::array<Eigen::Vector3d, 4>& x);

/// Hessian of the signed volume with respect to the 12 vertex coordinates.
Mat12 volume_hessian(const std::array<Eigen::Vector3d, 4>& x);

/// Voigt vector (engineering shear) of a symmetric 3x3 strain tensor.
inline Vec6 strain_to_voigt(const Mat3& e) {
  Vec6 v;
  v << e(0, 0), e(1, 1), e(2, 2), 2.0 * e(1, 2), 2.0 * e(0, 2), 2.0 * e(0, 1);
  return v;
}
/// Symmetric 3x3 stress tensor of a Voigt stress vector.
inline Mat3 voigt_to_stress(const Vec6& s) {
  Mat3 m;
  m << s(0), s(5), s(4), s(5), s(1), s(3), s(4), s(3), s(2);
  return m;
}
/// Voigt stress vector of a symmetric 3x3 stress tensor.
inline Vec6 stress_to_voigt(const Mat3& s) {
  Vec6 v;
  v << s(0, 0), s(1, 1), s(2, 2), s(1, 2), s(0, 2), s(0, 1);
  return v;
}

}  // namespace viscera::tissue
