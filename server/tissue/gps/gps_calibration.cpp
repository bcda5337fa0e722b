#include "viscera/tissue/gps/gps_calibration.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>

namespace viscera::tissue {

namespace {
/// J+ = J^T (J J^T)^-1: J has full row rank 6 for any tetrahedron of positive volume (its six edge
/// directions span the symmetric strains), so the normal equations hold, and a 6x6 Cholesky costs
/// a fifth of a complete orthogonal decomposition of J (a cut calibrates its children on the
/// physics thread). A tetrahedron too flat for it falls back on the decomposition.
Eigen::Matrix<double, 12, 6> pseudo_inverse(const Mat6x12& J) {
  const Eigen::LLT<Mat6> llt(J * J.transpose());
  if (llt.info() == Eigen::Success) return J.transpose() * llt.solve(Mat6::Identity());
  return J.completeOrthogonalDecomposition().pseudoInverse();
}
}  // namespace

Mat6 gps_edge_hessian(const std::array<Eigen::Vector3d, 4>& rest, const Mat6& D) {
  const Mat6x12 J = elongation_jacobian(rest);
  const Eigen::Matrix<double, 12, 6> Jp = pseudo_inverse(J);
  const Mat6 H = Jp.transpose() * linear_fe_stiffness(rest, D) * Jp;
  return 0.5 * (H + H.transpose());
}

Mat6 calibrate_gps_pseudoinverse(const std::array<Eigen::Vector3d, 4>& rest, const Mat6& D) {
  const Mat6 H = gps_edge_hessian(rest, D);
  Vec6 inv_length;
  for (int e = 0; e < 6; ++e) inv_length(e) = 1.0 / (rest[kTetEdges[e][1]] - rest[kTetEdges[e][0]]).norm();
  return inv_length.asDiagonal() * H;
}

Mat6 calibrate_gps_edge_modes(const std::array<Eigen::Vector3d, 4>& rest, const Mat6& D) {
  const Mat12 K = linear_fe_stiffness(rest, D);
  // Square system [J; rigid] u = [e_k; 0]: the displacement that elongates edge k by one unit,
  // changes no other edge and has no component along the six rigid-body modes.
  Mat12 A = Mat12::Zero();
  A.topRows<6>() = elongation_jacobian(rest);
  const Eigen::Vector3d centroid = (rest[0] + rest[1] + rest[2] + rest[3]) / 4.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d r = rest[i] - centroid;
    for (int a = 0; a < 3; ++a) {
      A(6 + a, 3 * i + a) = 1.0;  // translation along axis a
      const Eigen::Vector3d w = Eigen::Vector3d::Unit(a).cross(r);  // rotation about axis a
      A.block<1, 3>(9 + a, 3 * i) = w.transpose();
    }
  }
  const Eigen::PartialPivLU<Mat12> lu(A);
  // Eq. (1) basis: a unit tension on edge e = (a,b) pushes a with +Y_e and b with -Y_e.
  Eigen::Matrix<double, 12, 6> P = Eigen::Matrix<double, 12, 6>::Zero();
  for (int e = 0; e < 6; ++e) {
    const int a = kTetEdges[e][0], b = kTetEdges[e][1];
    const Eigen::Vector3d Y = rest[b] - rest[a];
    P.block<3, 1>(3 * a, e) = Y;
    P.block<3, 1>(3 * b, e) = -Y;
  }
  const Eigen::HouseholderQR<Eigen::Matrix<double, 12, 6>> qr(P);
  Mat6 C;
  for (int k = 0; k < 6; ++k) {
    Vec12 rhs = Vec12::Zero();
    rhs(k) = 1.0;
    const Vec12 u = lu.solve(rhs);
    const Vec12 f = -K * u;  // FE forces of the mode
    C.col(k) = qr.solve(f);  // over-determined by a factor of two, consistent (exact)
  }
  return C;
}

Vec6 volume_in_elongations(const std::array<Eigen::Vector3d, 4>& rest) {
  return pseudo_inverse(elongation_jacobian(rest)).transpose() * volume_gradient(rest);
}

}  // namespace viscera::tissue
