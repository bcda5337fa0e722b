#include "viscera/tissue/fem/polar_decomposition.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace viscera::tissue {

namespace {
Eigen::Matrix3d rotation_from_svd(const Eigen::Matrix3d& F) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) = -U.col(2);  // smallest singular value
  return U * V.transpose();
}
}  // namespace

Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F) {
  const double det = F.determinant();
  const double scale = F.squaredNorm();
  if (!(det > 1e-12 * scale * std::sqrt(scale))) return rotation_from_svd(F);
  Eigen::Matrix3d R = F;
  for (int it = 0; it < 30; ++it) {
    const Eigen::Matrix3d inv_t = R.inverse().transpose();
    // Frobenius-norm scaling (Higham 1986) speeds up the first iterations far from orthogonal.
    const double gamma = std::sqrt(std::sqrt(inv_t.squaredNorm() / R.squaredNorm()));
    const Eigen::Matrix3d next = 0.5 * (gamma * R + inv_t / gamma);
    const double change = (next - R).squaredNorm();
    R = next;
    if (change < 1e-28) break;
  }
  return R;
}

}  // namespace viscera::tissue
