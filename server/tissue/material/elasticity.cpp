#include "viscera/tissue/material/elasticity.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "viscera/common/input_error.hpp"

namespace viscera::tissue {

using common::InputError;

namespace {
std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}
void require(bool ok, const std::string& source, const char* field, double value, const char* why) {
  if (!ok) throw InputError(source, 0, field, num(value) + " " + why);
}
}  // namespace

Mat6 elasticity_matrix(const IsotropicElasticity& m, const std::string& source) {
  require(std::isfinite(m.youngs_modulus_pa) && m.youngs_modulus_pa > 0, source, "youngs_modulus_pa", m.youngs_modulus_pa,
          "must be a positive number of pascals");
  require(std::isfinite(m.poisson_ratio) && m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5, source, "poisson_ratio", m.poisson_ratio,
          "must lie in (-1, 0.5)");
  const double E = m.youngs_modulus_pa, nu = m.poisson_ratio;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double mu = E / (2 * (1 + nu));
  Mat6 D = Mat6::Zero();
  D.topLeftCorner<3, 3>().setConstant(lambda);
  D.topLeftCorner<3, 3>().diagonal().array() += 2 * mu;
  D.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return D;
}

Mat6 elasticity_matrix(const TransverselyIsotropicElasticity& m, const std::string& source) {
  require(std::isfinite(m.plane_youngs_modulus_pa) && m.plane_youngs_modulus_pa > 0, source, "plane_youngs_modulus_pa", m.plane_youngs_modulus_pa,
          "must be a positive number of pascals");
  require(std::isfinite(m.fibre_youngs_modulus_pa) && m.fibre_youngs_modulus_pa > 0, source, "fibre_youngs_modulus_pa", m.fibre_youngs_modulus_pa,
          "must be a positive number of pascals");
  require(std::isfinite(m.fibre_shear_modulus_pa) && m.fibre_shear_modulus_pa > 0, source, "fibre_shear_modulus_pa", m.fibre_shear_modulus_pa,
          "must be a positive number of pascals");
  require(std::isfinite(m.plane_poisson_ratio) && std::abs(m.plane_poisson_ratio) < 1.0, source, "plane_poisson_ratio", m.plane_poisson_ratio,
          "must lie in (-1, 1)");
  require(std::isfinite(m.fibre_plane_poisson_ratio), source, "fibre_plane_poisson_ratio", m.fibre_plane_poisson_ratio, "must be finite");
  const double n = m.fibre_direction.norm();
  require(std::isfinite(n) && n > 0, source, "fibre_direction", n, "(its length) must be non-zero");

  // Compliance in the material frame with the fibre along local z.
  const double Ep = m.plane_youngs_modulus_pa, Ef = m.fibre_youngs_modulus_pa;
  const double nup = m.plane_poisson_ratio, nufp = m.fibre_plane_poisson_ratio;
  const double Gp = Ep / (2 * (1 + nup)), Gf = m.fibre_shear_modulus_pa;
  Mat6 S = Mat6::Zero();
  S(0, 0) = S(1, 1) = 1 / Ep;
  S(2, 2) = 1 / Ef;
  S(0, 1) = S(1, 0) = -nup / Ep;
  S(0, 2) = S(2, 0) = S(1, 2) = S(2, 1) = -nufp / Ef;
  S(3, 3) = S(4, 4) = 1 / Gf;  // yz, xz: planes containing the fibre (z)
  S(5, 5) = 1 / Gp;  // xy: the isotropic plane
  Eigen::LLT<Mat6> llt(S);
  if (llt.info() != Eigen::Success)
    throw InputError(source, 0, "fibre_plane_poisson_ratio",
                     num(nufp) +
                         " with the other constants gives a compliance that is not positive "
                         "definite (unphysical material)");
  const Mat6 D_local = S.inverse();

  // Rotation taking local z onto the fibre direction.
  const Eigen::Vector3d f = m.fibre_direction / n;
  const Eigen::Vector3d helper = std::abs(f.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = f.cross(helper).normalized();
  const Eigen::Vector3d v = f.cross(u);
  Mat3 R;  // columns: local x, y, z expressed in the global frame
  R.col(0) = u;
  R.col(1) = v;
  R.col(2) = f;
  Mat6 D = rotate_elasticity(D_local, R);
  D = 0.5 * (D + D.transpose());
  check_elasticity_matrix(D, source);
  return D;
}

void check_elasticity_matrix(const Mat6& D, const std::string& source) {
  if (!D.allFinite()) throw InputError(source, 0, "D", "has non-finite entries");
  if ((D - D.transpose()).norm() > 1e-12 * D.norm()) throw InputError(source, 0, "D", "is not symmetric");
  Eigen::LLT<Mat6> llt(D);
  if (llt.info() != Eigen::Success) throw InputError(source, 0, "D", "is not positive definite");
}

Mat6 rotate_elasticity(const Mat6& D, const Mat3& R) {
  // Stress transformation in Voigt form (Bond matrix), sigma' = M sigma for sigma' = R sigma R^T.
  // With engineering shear strains, eps' = N eps with N = M^-T, so D' = M D M^T.
  Mat6 M;
  const auto r = [&](int i, int j) { return R(i, j); };
  const int pair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  for (int I = 0; I < 6; ++I) {
    const int i = pair[I][0], j = pair[I][1];
    for (int J = 0; J < 6; ++J) {
      const int k = pair[J][0], l = pair[J][1];
      M(I, J) = (k == l) ? r(i, k) * r(j, l) : r(i, k) * r(j, l) + r(i, l) * r(j, k);
    }
  }
  return M * D * M.transpose();
}

double reuss_bulk_modulus(const Mat6& D) {
  Vec6 m;
  m << 1, 1, 1, 0, 0, 0;
  return 1.0 / m.dot(D.ldlt().solve(m));
}

double max_wave_modulus(const Mat6& D) {
  Eigen::SelfAdjointEigenSolver<Mat6> es(D, Eigen::EigenvaluesOnly);
  return es.eigenvalues().maxCoeff();
}

}  // namespace viscera::tissue
