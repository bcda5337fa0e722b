// Elasticity matrices against their defining compliances.  // SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/material/elasticity.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
using namespace viscera::common;
namespace test = viscera::tissue::test;

TEST(Elasticity, IsotropicComplianceHasOneOverEAndPoisson) {
  const double E = 4e3, nu = 0.4;
  const Mat6 S = elasticity_matrix(IsotropicElasticity{E, nu}).inverse();
  EXPECT_NEAR(S(0, 0) * E, 1.0, 1e-12);
  EXPECT_NEAR(S(0, 1) * E, -nu, 1e-12);
  EXPECT_NEAR(S(3, 3) * E / (2 * (1 + nu)), 1.0, 1e-12);  // engineering shear: 1/G
  EXPECT_NEAR(reuss_bulk_modulus(elasticity_matrix(IsotropicElasticity{E, nu})), E / (3 * (1 - 2 * nu)), 1e-9);
}

TEST(Elasticity, TransverselyIsotropicReducesToIsotropic) {
  const double E = 7e3, nu = 0.3;
  TransverselyIsotropicElasticity ti{E, nu, E, nu, E / (2 * (1 + nu)), Vec3(1, 2, 3)};
  const Mat6 D = elasticity_matrix(ti);
  EXPECT_LT((D - elasticity_matrix(IsotropicElasticity{E, nu})).norm(), 1e-9 * D.norm());
}

TEST(Elasticity, TransverselyIsotropicResponseAlongAnyFibreDirection) {
  std::mt19937_64 rng(7);
  const double Ep = 2e3, nup = 0.45, Ef = 20e3, nufp = 0.35, Gf = 3e3;
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 R = test::random_rotation(rng);
    const Vec3 a = R.col(0), b = R.col(1);
    const Mat6 S = elasticity_matrix(TransverselyIsotropicElasticity{Ep, nup, Ef, nufp, Gf, 3.0 * a}).inverse();
    const auto strain = [&](const Mat3& sigma) {
      const Vec6 e = S * stress_to_voigt(sigma);
      Mat3 m;  // engineering shear back to tensor shear
      m << e(0), e(5) / 2, e(4) / 2, e(5) / 2, e(1), e(3) / 2, e(4) / 2, e(3) / 2, e(2);
      return m;
    };
    const Mat3 fibre = strain(a * a.transpose());
    EXPECT_NEAR(a.dot(fibre * a) * Ef, 1.0, 1e-9);
    EXPECT_NEAR(b.dot(fibre * b) * Ef, -nufp, 1e-9);
    const Mat3 plane = strain(b * b.transpose());
    EXPECT_NEAR(b.dot(plane * b) * Ep, 1.0, 1e-9);
    EXPECT_NEAR(a.dot(plane * a) * Ef, -nufp, 1e-9);  // reciprocity S_pf = S_fp
    const Mat3 shear = strain(a * b.transpose() + b * a.transpose());
    EXPECT_NEAR(2.0 * a.dot(shear * b) * Gf, 1.0, 1e-9);
  }
}

TEST(Elasticity, RotationOfDMatchesRotatingTheStrain) {
  std::mt19937_64 rng(3);
  const Mat6 D = test::random_spd(rng, 1e3);
  const Mat3 R = test::random_rotation(rng);
  Mat3 eps;
  eps << 1, 2, 3, 2, 4, 5, 3, 5, 6;
  eps *= 1e-3;
  // sigma' = R sigma R^T must equal D' applied to eps' = R eps R^T.
  const Mat3 sigma_rot = R * voigt_to_stress(D * strain_to_voigt(eps)) * R.transpose();
  const Mat3 sigma_direct = voigt_to_stress(rotate_elasticity(D, R) * strain_to_voigt(R * eps * R.transpose()));
  EXPECT_LT((sigma_rot - sigma_direct).norm(), 1e-12 * sigma_rot.norm());
}

TEST(Elasticity, InvalidConstantsNameTheField) {
  const auto message = [](auto f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] {
              elasticity_matrix(IsotropicElasticity{5e3, 0.5}, "liver.json");
            }).find("liver.json: poisson_ratio: 0.5"),
            std::string::npos);
  EXPECT_NE(message([] { elasticity_matrix(IsotropicElasticity{-1, 0.3}); }).find("youngs_modulus_pa"), std::string::npos);
  EXPECT_NE(message([] { elasticity_matrix(IsotropicElasticity{std::nan(""), 0.3}); }).find("youngs_modulus_pa"), std::string::npos);
  EXPECT_NE(message([] {
              elasticity_matrix(TransverselyIsotropicElasticity{1e3, 0.3, 1e3, 3.0, 1e3, Vec3::UnitZ()});
            }).find("fibre_plane_poisson_ratio"),
            std::string::npos);
  EXPECT_NE(message([] {
              elasticity_matrix(TransverselyIsotropicElasticity{1e3, 0.3, 1e3, 0.3, 1e3, Vec3::Zero()});
            }).find("fibre_direction"),
            std::string::npos);
  Mat6 bad = Mat6::Identity();
  bad(0, 0) = -1;
  EXPECT_NE(message([&] { check_elasticity_matrix(bad, "m.json"); }).find("not positive definite"), std::string::npos);
}
