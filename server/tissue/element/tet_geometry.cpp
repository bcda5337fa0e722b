#include "viscera/tissue/element/tet_geometry.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::tissue {

Mat6x12 strain_displacement(const Mat3& dm_inv) {
  const Eigen::Matrix<double, 4, 3> g = shape_gradients(dm_inv);
  Mat6x12 B = Mat6x12::Zero();
  for (int i = 0; i < 4; ++i) {
    const double gx = g(i, 0), gy = g(i, 1), gz = g(i, 2);
    const int c = 3 * i;
    B(0, c) = gx;
    B(1, c + 1) = gy;
    B(2, c + 2) = gz;
    B(3, c + 1) = gz;
    B(3, c + 2) = gy;
    B(4, c) = gz;
    B(4, c + 2) = gx;
    B(5, c) = gy;
    B(5, c + 1) = gx;
  }
  return B;
}

Mat12 linear_fe_stiffness(const std::array<Eigen::Vector3d, 4>& x, const Mat6& D) {
  const Mat3 dm = edge_matrix(x);
  const double volume = dm.determinant() / 6.0;
  const Mat6x12 B = strain_displacement(dm.inverse());
  return volume * B.transpose() * D * B;
}

Mat6x12 elongation_jacobian(const std::array<Eigen::Vector3d, 4>& x) {
  Mat6x12 J = Mat6x12::Zero();
  for (int e = 0; e < 6; ++e) {
    const int a = kTetEdges[e][0], b = kTetEdges[e][1];
    const Eigen::Vector3d n = (x[b] - x[a]).normalized();
    J.block<1, 3>(e, 3 * a) = -n.transpose();
    J.block<1, 3>(e, 3 * b) = n.transpose();
  }
  return J;
}

Vec12 volume_gradient(const std::array<Eigen::Vector3d, 4>& x) {
  const Eigen::Vector3d e1 = x[1] - x[0], e2 = x[2] - x[0], e3 = x[3] - x[0];
  Vec12 g;
  const Eigen::Vector3d g1 = e2.cross(e3) / 6.0, g2 = e3.cross(e1) / 6.0, g3 = e1.cross(e2) / 6.0;
  g.segment<3>(3) = g1;
  g.segment<3>(6) = g2;
  g.segment<3>(9) = g3;
  g.segment<3>(0) = -(g1 + g2 + g3);
  return g;
}

namespace {
Mat3 skew(const Eigen::Vector3d& a) {
  Mat3 s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}
}  // namespace

Mat12 volume_hessian(const std::array<Eigen::Vector3d, 4>& x) {
  // V = e1 . (e2 x e3) / 6 with e_k = x_k - x0. Second derivatives in e: d(e2 x e3)/de2 =
  // -[e3]x, d(e2 x e3)/de3 = [e2]x, d(e3 x e1)/de3 = -[e1]x; diagonal blocks vanish.
  const Eigen::Vector3d e1 = x[1] - x[0], e2 = x[2] - x[0], e3 = x[3] - x[0];
  Eigen::Matrix<double, 9, 9> He = Eigen::Matrix<double, 9, 9>::Zero();
  const Mat3 h12 = -skew(e3) / 6.0, h13 = skew(e2) / 6.0, h23 = -skew(e1) / 6.0;
  He.block<3, 3>(0, 3) = h12;
  He.block<3, 3>(3, 0) = h12.transpose();
  He.block<3, 3>(0, 6) = h13;
  He.block<3, 3>(6, 0) = h13.transpose();
  He.block<3, 3>(3, 6) = h23;
  He.block<3, 3>(6, 3) = h23.transpose();
  // e = T x with T = [-I I 0 0; -I 0 I 0; -I 0 0 I].
  Eigen::Matrix<double, 9, 12> T = Eigen::Matrix<double, 9, 12>::Zero();
  for (int k = 0; k < 3; ++k) {
    T.block<3, 3>(3 * k, 0) = -Mat3::Identity();
    T.block<3, 3>(3 * k, 3 * (k + 1)) = Mat3::Identity();
  }
  return T.transpose() * He * T;
}

}  // namespace viscera::tissue
