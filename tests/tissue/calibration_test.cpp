// The GPS equals linear FE at small strain (docs/MODEL.md section 1), and the paper's calibration  // SPDX-License-Identifier: Apache-2.0
// route agrees with the pseudo-inverse route.
#include <gtest/gtest.h>

#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_calibration.hpp"
#include "viscera/tissue/gps/gps_model.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

double relative(const Mat6& a, const Mat6& b) { return (a - b).norm() / b.norm(); }

// max over random u (|u_i| = 1e-8 x element size) of |f_gps - f_fe| / |f_fe|.
double small_strain_force_error(const ForceModel& gps, const std::array<Vec3, 4>& rest, const Mat6& D, std::mt19937_64& rng) {
  const Mat12 K = linear_fe_stiffness(rest, D);
  double size = 0.0;
  for (const auto& [a, b] : kTetEdges) size = std::max(size, (rest[b] - rest[a]).norm());
  std::normal_distribution<double> n;
  double worst = 0.0;
  for (int trial = 0; trial < 5; ++trial) {
    Vec12 u;
    for (int k = 0; k < 12; ++k) u(k) = n(rng);
    u *= 1e-8 * size / u.norm();
    std::vector<Vec3> x(rest.begin(), rest.end()), f(4, Vec3::Zero());
    for (int i = 0; i < 4; ++i) {
      x[i] += u.segment<3>(3 * i);
      u.segment<3>(3 * i) = x[i] - rest[i];  // the displacement the positions actually represent
    }
    gps.add_forces(x, f);
    Vec12 fg;
    for (int i = 0; i < 4; ++i) fg.segment<3>(3 * i) = f[i];
    const Vec12 fe = -K * u;
    worst = std::max(worst, (fg - fe).norm() / fe.norm());
  }
  return worst;
}

std::vector<Mat6> materials(std::mt19937_64& rng) {
  return {test::soft_tissue(), elasticity_matrix(TransverselyIsotropicElasticity{2e3, 0.45, 20e3, 0.35, 3e3, Vec3(1, 1, 0)}),
          test::random_spd(rng, 1e4)};
}

}  // namespace

TEST(GpsCalibration, BothRoutesAgreeOnRandomTets) {
  std::mt19937_64 rng(1);
  double worst = 0.0;
  for (const Mat6& D : materials(rng))
    for (int trial = 0; trial < 50; ++trial) {
      const auto x = test::random_tet(rng, 0.01, 0.1);
      worst = std::max(worst, relative(calibrate_gps_edge_modes(x, D), calibrate_gps_pseudoinverse(x, D)));
    }
  std::cout << "[ figure ] calibration routes, max relative difference on random tets: " << worst << "\n";
  EXPECT_LT(worst, 1e-10);
}

TEST(GpsCalibration, BothRoutesAgreeOnEveryLiverTet) {
  const auto liver = test::liver2();
  const Mat6 D = test::soft_tissue();
  double worst = 0.0;
  for (std::size_t e = 0; e < liver->tet_count(); ++e) {
    const Tet& t = liver->tets[e];
    const std::array<Vec3, 4> x{liver->nodes[t[0]], liver->nodes[t[1]], liver->nodes[t[2]], liver->nodes[t[3]]};
    worst = std::max(worst, relative(calibrate_gps_edge_modes(x, D), calibrate_gps_pseudoinverse(x, D)));
  }
  std::cout << "[ figure ] calibration routes, max relative difference over liver2: " << worst << "\n";
  EXPECT_LT(worst, 1e-10);
}

TEST(GpsCalibration, CalibratedTensionsReproduceTheFeStiffness) {
  // K_fe = J^T H J exactly: the 6 edge elongations carry all of the element's strain energy.
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 20; ++trial) {
    const auto x = test::random_tet(rng);
    const Mat6 D = test::random_spd(rng, 1e3);
    const Mat6x12 J = elongation_jacobian(x);
    const Mat12 K = linear_fe_stiffness(x, D);
    EXPECT_LT((J.transpose() * gps_edge_hessian(x, D) * J - K).norm(), 1e-10 * K.norm());
  }
}

TEST(GpsSmallStrain, ForcesEqualLinearFeOnRandomTets) {
  std::mt19937_64 rng(3);
  for (const Mat6& D : materials(rng))
    for (GpsVariant variant : {GpsVariant::paper, GpsVariant::energy_consistent})
      for (double volume_fraction : {0.0, 0.5}) {
        double worst = 0.0;
        for (int trial = 0; trial < 30; ++trial) {
          const auto x = test::random_tet(rng);
          const GpsModel gps(test::single_tet_mesh(x), {D}, {}, {variant, volume_fraction});
          worst = std::max(worst, small_strain_force_error(gps, x, D, rng));
        }
        std::cout << "[ figure ] GPS vs linear FE at |u| = 1e-8 h, variant " << static_cast<int>(variant) << ", volume " << volume_fraction
                  << ": max relative force error " << worst << "\n";
        EXPECT_LT(worst, 1e-6);
      }
}

TEST(GpsSmallStrain, ForcesEqualLinearFeOnEveryLiverTet) {
  const auto liver = test::liver2();
  const Mat6 D = test::soft_tissue();
  std::mt19937_64 rng(4);
  double worst = 0.0;
  for (std::size_t e = 0; e < liver->tet_count(); ++e) {
    const Tet& t = liver->tets[e];
    // Each tet about its own centroid, so that positions carry the tiny displacement with full
    // precision (a liver tet 10 cm from the origin loses 4 digits of it to rounding).
    const Vec3 c = (liver->nodes[t[0]] + liver->nodes[t[1]] + liver->nodes[t[2]] + liver->nodes[t[3]]) / 4;
    const std::array<Vec3, 4> x{liver->nodes[t[0]] - c, liver->nodes[t[1]] - c, liver->nodes[t[2]] - c, liver->nodes[t[3]] - c};
    const GpsModel gps(test::single_tet_mesh(x), {D});
    worst = std::max(worst, small_strain_force_error(gps, x, D, rng));
  }
  std::cout << "[ figure ] GPS vs linear FE over liver2 tets: max relative force error " << worst << "\n";
  EXPECT_LT(worst, 1e-6);
}

TEST(GpsSmallStrain, WholeLiverForcesEqualLinearFe) {
  // Assembled over the whole organ: same forces as the FE model for a tiny random displacement.
  const auto liver = test::liver2();
  const GpsModel gps(liver, {test::soft_tissue()});
  const FiniteElementModel fe(liver, FeKind::linear, {test::soft_tissue()});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n;
  std::vector<Vec3> x = liver->nodes;
  for (auto& p : x) p += 1e-10 * Vec3(n(rng), n(rng), n(rng));
  std::vector<Vec3> fg(x.size(), Vec3::Zero()), ff(x.size(), Vec3::Zero());
  gps.add_forces(x, fg);
  fe.add_forces(x, ff);
  double num = 0, den = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    num += (fg[i] - ff[i]).squaredNorm();
    den += ff[i].squaredNorm();
  }
  EXPECT_LT(std::sqrt(num / den), 1e-6);
}

TEST(GpsPaperForm, PaperConstantsAreTheCalibratedC) {
  std::mt19937_64 rng(6);
  const auto x = test::random_tet(rng);
  const Mat6 D = test::soft_tissue();
  for (double vf : {0.0, 0.7}) {
    const GpsModel gps(test::single_tet_mesh(x), {D}, {}, {GpsVariant::paper, vf});
    EXPECT_LT(relative(gps.paper_constants(0), calibrate_gps_edge_modes(x, D)), 1e-10);
  }
}
