// Element tangents against central finite differences of the forces (an independent path).  // SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {
Mat12 finite_difference_tangent(const ForceModel& m, std::vector<Vec3> x, double h) {
  Mat12 K;
  for (int c = 0; c < 12; ++c) {
    std::vector<Vec3> fp(4, Vec3::Zero()), fm(4, Vec3::Zero());
    x[c / 3][c % 3] += h;
    m.add_forces(x, fp);
    x[c / 3][c % 3] -= 2 * h;
    m.add_forces(x, fm);
    x[c / 3][c % 3] += h;
    for (int r = 0; r < 12; ++r) K(r, c) = -(fp[r / 3][r % 3] - fm[r / 3][r % 3]) / (2 * h);
  }
  return K;
}
}  // namespace

TEST(Tangent, MatchesFiniteDifferencesAtLargeDeformation) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 10; ++trial) {
    const auto rest = test::random_tet(rng);
    auto mesh = test::single_tet_mesh(rest);
    std::vector<Vec3> x(rest.begin(), rest.end());
    const Mat3 F = Mat3::Identity() + 0.2 * Mat3::Random();
    for (auto& p : x) p = F * p + 0.001 * Vec3(n(rng), n(rng), n(rng));
    const GpsModel paper(mesh, {test::soft_tissue()});
    const GpsModel energy(mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.0});
    const GpsModel volume(mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.6});
    const FiniteElementModel linear(mesh, FeKind::linear, {test::soft_tissue()});
    GpsOptions qlv_options;
    qlv_options.mechanisms.stiffening.b = 8.0;
    const GpsModel qlv(mesh, {test::soft_tissue()}, {}, qlv_options);
    GpsOptions fung_energy{GpsVariant::energy_consistent, 0.4};
    fung_energy.mechanisms.stiffening.b = 8.0;
    fung_energy.mechanisms.stiffening.form = GpsStiffening::Form::energy;
    const GpsModel qlv_energy(mesh, {test::soft_tissue()}, {}, fung_energy);
    GpsOptions asymmetric = fung_energy;
    asymmetric.mechanisms.asymmetry.compression_ratio = 0.4;
    const GpsModel qlv_asymmetric(mesh, {test::soft_tissue()}, {}, asymmetric);
    for (const ForceModel* m :
         {static_cast<const ForceModel*>(&paper), static_cast<const ForceModel*>(&energy), static_cast<const ForceModel*>(&volume),
          static_cast<const ForceModel*>(&linear), static_cast<const ForceModel*>(&qlv), static_cast<const ForceModel*>(&qlv_energy),
          static_cast<const ForceModel*>(&qlv_asymmetric)}) {
      const Mat12 K = m->element_tangent(x, 0);
      const Mat12 Kfd = finite_difference_tangent(*m, x, 1e-7);
      EXPECT_LT((K - Kfd).norm(), 1e-6 * K.norm()) << m->name();
    }
    // Energy-consistent tangents are symmetric (they are Hessians), with Fung's stiffening in its
    // energy form too; the paper form's is not, nor the edge map's.
    EXPECT_LT((energy.element_tangent(x, 0) - energy.element_tangent(x, 0).transpose()).norm(), 1e-12 * energy.element_tangent(x, 0).norm());
    const Mat12 Kq = qlv_energy.element_tangent(x, 0);
    EXPECT_LT((Kq - Kq.transpose()).norm(), 1e-12 * Kq.norm());
    EXPECT_GT((paper.element_tangent(x, 0) - paper.element_tangent(x, 0).transpose()).norm(), 1e-4 * paper.element_tangent(x, 0).norm());
  }
}

TEST(Tangent, EnergyConsistentForcesAreTheEnergyGradient) {
  std::mt19937_64 rng(22);
  const auto rest = test::random_tet(rng);
  GpsOptions fung{GpsVariant::energy_consistent, 0.5};
  fung.mechanisms.stiffening.b = 10.0;
  fung.mechanisms.stiffening.form = GpsStiffening::Form::energy;
  const GpsModel linear(test::single_tet_mesh(rest), {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.5});
  const GpsModel stiffening(test::single_tet_mesh(rest), {test::soft_tissue()}, {}, fung);
  fung.mechanisms.asymmetry.compression_ratio = 2.5;
  const GpsModel asymmetric(test::single_tet_mesh(rest), {test::soft_tissue()}, {}, fung);
  std::vector<Vec3> x(rest.begin(), rest.end());
  for (auto& p : x) p = 1.1 * p + 0.001 * Vec3::Random();
  for (const GpsModel* energy : {&linear, &stiffening, &asymmetric}) {
    std::vector<Vec3> f(4, Vec3::Zero());
    energy->add_forces(x, f);
    const double h = 1e-8;
    for (int c = 0; c < 12; ++c) {
      auto xp = x, xm = x;
      xp[c / 3][c % 3] += h;
      xm[c / 3][c % 3] -= h;
      const double grad = (energy->energy(xp) - energy->energy(xm)) / (2 * h);
      EXPECT_NEAR(-grad, f[c / 3][c % 3], 1e-6 * f[c / 3].norm() + 1e-12);
    }
  }
}
