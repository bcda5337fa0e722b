// The large-strain GPS (gps_model.hpp, GpsOptions::large_strain; docs/TISSUE.md "Large strain")  // SPDX-License-Identifier: Apache-2.0
// against other code paths: its neo-Hookean backbone's forces are the gradient of its energy and
// its tangent their derivative (central differences), through inversion too; the SIMD force loop
// equals the scalar backbone summed element by element; the whole model's forces are the
// gradient of its energy with the mechanisms on; at rest its tangent is the GPS's, so linear FE's
// (calibrated elsewhere to 1e-12); a rigid rotation gives no force; a model that follows a cut in
// place equals one built on the cut mesh, bit for bit.
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/gps/neo_hookean_backbone.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

std::vector<Vec3> forces(const ForceModel& m, const std::vector<Vec3>& x) {
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  m.add_forces(x, f);
  return f;
}

double largest(const std::vector<Vec3>& f) {
  double s = 0;
  for (const auto& v : f) s = std::max(s, v.norm());
  return s;
}

/// A random deformation of the mesh: each node moved by up to `amount` of the mesh's size.
std::vector<Vec3> deformed(const TetMesh& mesh, double amount, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> x = mesh.nodes;
  for (auto& p : x) p += amount * Vec3(u(rng), u(rng), u(rng));
  return x;
}

GpsOptions large_strain(GpsMechanisms mech = {}) {
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.large_strain = true;
  o.mechanisms = std::move(mech);
  return o;
}

}  // namespace

TEST(NeoHookeanBackbone, ForcesAreTheEnergysGradientAndTheTangentTheirDerivativeThroughInversion) {
  std::mt19937_64 rng(5);
  const NeoHookean m = neo_hookean_of(test::soft_tissue());
  for (int trial = 0; trial < 20; ++trial) {
    const auto rest = test::random_tet(rng);
    const Mat3 dm_inv = rest_shape_inverse(rest);
    const double V0 = signed_volume(rest[0], rest[1], rest[2], rest[3]);
    auto x = rest;
    std::uniform_real_distribution<double> u(-1, 1);
    // Up to 60% of the element's size: many of these are inverted.
    for (auto& p : x) p = test::random_rotation(rng) * p + 0.006 * Vec3(u(rng), u(rng), u(rng));
    const Vec12 f = neo_hookean_forces(m, x, dm_inv, V0);
    const Mat12 K = neo_hookean_tangent(m, x, dm_inv, V0);
    const double h = 1e-7;
    for (int c = 0; c < 12; ++c) {
      auto xp = x, xm = x;
      xp[c / 3][c % 3] += h;
      xm[c / 3][c % 3] -= h;
      const double dE = (neo_hookean_energy(m, xp, dm_inv, V0) - neo_hookean_energy(m, xm, dm_inv, V0)) / (2 * h);
      EXPECT_NEAR(f(c), -dE, 1e-6 * f.norm() + 1e-12) << trial << " " << c;
      const Vec12 dF = (neo_hookean_forces(m, xp, dm_inv, V0) - neo_hookean_forces(m, xm, dm_inv, V0)) / (2 * h);
      EXPECT_LT((K.col(c) + dF).norm(), 1e-6 * K.norm()) << trial << " " << c;
    }
  }
  // At rest: no energy, no force; the tangent is linear FE's (Lame lambda = lam - mu).
  const auto rest = test::random_tet(rng);
  EXPECT_NEAR(neo_hookean_energy(m, rest, rest_shape_inverse(rest), 1.0), 0.0, 1e-9 * m.mu);
  EXPECT_LT(neo_hookean_forces(m, rest, rest_shape_inverse(rest), 1.0).norm(), 1e-9 * m.mu);
}

TEST(LargeStrainGps, TheSimdLoopIsTheScalarBackboneAndTheTangentAtRestIsTheGps) {
  const auto mesh = test::liver2();
  const GpsModel model(mesh, {test::soft_tissue()}, {}, large_strain());
  const GpsModel gps(mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.0});
  std::mt19937_64 rng(3);
  const auto x = deformed(*mesh, 0.004, rng);  // about 20% strain on the 18 mm edges
  std::vector<Vec3> scalar(x.size(), Vec3::Zero());
  for (std::size_t e = 0; e < mesh->tet_count(); ++e) {
    const auto p = model.gather(x, e), r = model.gather(mesh->nodes, e);
    const Vec12 fe = neo_hookean_forces(model.backbone(e), p, rest_shape_inverse(r), signed_volume(r[0], r[1], r[2], r[3]));
    for (int i = 0; i < 4; ++i) scalar[mesh->tets[e][i]] += fe.segment<3>(3 * i);
  }
  const auto simd = forces(model, x);
  double worst = 0;
  for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, (simd[i] - scalar[i]).norm());
  EXPECT_LT(worst, 1e-9 * largest(scalar));
  EXPECT_EQ(model.name(), "gps_large_strain");
  for (std::size_t e = 0; e < mesh->tet_count(); e += 97) {
    const Mat12 a = model.element_tangent(mesh->nodes, e), b = gps.element_tangent(mesh->nodes, e);
    EXPECT_LT((a - b).norm(), 1e-9 * b.norm()) << e;
  }
}

TEST(LargeStrainGps, TheTangentIsTheForcesDerivativeWithTheEdgeMapAndTheForcesTheEnergysGradient) {
  const auto mesh = test::single_tet_mesh({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0, 0, 0.01)});
  GpsMechanisms mech;
  mech.stiffening.b = 3;  // the edge-map form: its departure from the linear edge response stays on the edges
  const GpsModel model(mesh, {test::soft_tissue()}, {}, large_strain(mech));
  std::mt19937_64 rng(8);
  for (int trial = 0; trial < 10; ++trial) {
    const auto x = deformed(*mesh, 0.002, rng);
    const auto f = forces(model, x);
    const auto K = model.element_tangent(x, 0);
    const double h = 1e-8;
    for (int c = 0; c < 12; ++c) {
      auto xp = x, xm = x;
      xp[c / 3][c % 3] += h;
      xm[c / 3][c % 3] -= h;
      const auto fp = forces(model, xp), fm = forces(model, xm);
      for (int r = 0; r < 12; ++r)  // the edge map is not an energy: its tangent is the forces' derivative
        EXPECT_NEAR(K(r, c), -(fp[r / 3][r % 3] - fm[r / 3][r % 3]) / (2 * h), 1e-5 * K.norm()) << trial;
    }
  }
  // Without the stiffening the model is conservative: its forces are its energy's gradient.
  const GpsModel elastic(mesh, {test::soft_tissue()}, {}, large_strain());
  const auto x = deformed(*mesh, 0.003, rng);
  const auto f = forces(elastic, x);
  const double h = 1e-8;
  for (int c = 0; c < 12; ++c) {
    auto xp = x, xm = x;
    xp[c / 3][c % 3] += h;
    xm[c / 3][c % 3] -= h;
    EXPECT_NEAR(f[c / 3][c % 3], -(elastic.energy(xp) - elastic.energy(xm)) / (2 * h), 1e-6 * largest(f)) << c;
  }
}

TEST(LargeStrainGps, ARigidRotationGivesNoForce) {
  const auto mesh = test::liver2();
  const GpsModel model(mesh, {test::soft_tissue()}, {}, large_strain());
  std::mt19937_64 rng(2);
  std::vector<Vec3> stretched = mesh->nodes;
  for (auto& p : stretched) p *= 1.01;
  const double scale = largest(forces(model, stretched));
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 R = test::random_rotation(rng);
    std::vector<Vec3> x = mesh->nodes;
    for (auto& p : x) p = R * p + Vec3(0.1, -0.2, 0.3);
    EXPECT_LT(largest(forces(model, x)), 1e-9 * scale) << trial;
  }
}

TEST(LargeStrainGps, RefusesWhatItCannotRepresent) {
  const auto mesh = test::liver2();
  GpsOptions paper = large_strain();
  paper.variant = GpsVariant::paper;
  EXPECT_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, paper), std::invalid_argument);
  GpsOptions volume = large_strain();
  volume.volume_stiffness_fraction = 0.5;
  EXPECT_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, volume), std::invalid_argument);
  std::mt19937_64 rng(1);
  EXPECT_THROW(GpsModel(mesh, {test::random_spd(rng, 1e4)}, {}, large_strain()), std::invalid_argument);
  // Memory relaxes the backbone's stress, with the bulk relaxing as the shear or not at all; not
  // together with stiffening or first-load softening.
  GpsMechanisms viscous;
  viscous.viscous.omega_rad_s = {10.0, 100.0};
  viscous.viscous.shear_weight = {0.2, 0.1};
  viscous.viscous.kelvin_voigt_time_s = 0.01;
  EXPECT_NO_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, large_strain(viscous)));
  GpsMechanisms no_bulk = viscous;
  no_bulk.viscous.bulk_weight = {0.0, 0.0};
  EXPECT_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, large_strain(no_bulk)), std::invalid_argument);  // with Kelvin-Voigt
  no_bulk.viscous.kelvin_voigt_time_s = 0.0;
  EXPECT_NO_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, large_strain(no_bulk)));
  GpsMechanisms other_bulk = no_bulk;
  other_bulk.viscous.bulk_weight = {0.1, 0.0};
  EXPECT_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, large_strain(other_bulk)), std::invalid_argument);
  GpsMechanisms stiffened = viscous;
  stiffened.stiffening.b = 2.0;
  EXPECT_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, large_strain(stiffened)), std::invalid_argument);
  GpsMechanisms softened = viscous;
  softened.softening.d = 0.3;
  EXPECT_THROW(GpsModel(mesh, {test::soft_tissue()}, {}, large_strain(softened)), std::invalid_argument);
}

TEST(LargeStrainGps, TheStiffnessGrowthBoundsTheTangentAtTheElementsLargestEdgeStrain) {
  // The explicit integrator shortens its step by sqrt(stiffness_growth(largest edge strain)): the
  // element tangent's largest eigenvalue, over random deformations of a regular and of a flat tet,
  // against its value at rest.
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& rest : {std::array<Vec3, 4>{Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.005, 0.00866, 0), Vec3(0.005, 0.00289, 0.00816)},
                           std::array<Vec3, 4>{Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0.003, 0.003, 0.004)}}) {
    const auto mesh = test::single_tet_mesh(rest);
    const GpsModel model(mesh, {test::soft_tissue()}, {}, large_strain());
    const auto top = [&](const std::vector<Vec3>& x) { return Eigen::SelfAdjointEigenSolver<Mat12>(model.element_tangent(x, 0)).eigenvalues()(11); };
    const double k0 = top(mesh->nodes);
    double closest = 0;  // the largest ratio of measured growth to the bound
    for (int t = 0; t < 4000; ++t) {
      const double e = 0.6 * std::abs(u(rng));
      Mat3 A;
      for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = u(rng);
      Eigen::JacobiSVD<Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Mat3 U = svd.matrixU(), V = svd.matrixV();
      if (U.determinant() < 0) U.col(0) *= -1;
      if (V.determinant() < 0) V.col(0) *= -1;
      Vec3 s;
      for (int i = 0; i < 3; ++i) s(i) = t % 3 == 0 ? 1 + e * (u(rng) > 0 ? 1 : -1) : 1 + e * u(rng);
      const Mat3 F = U * s.asDiagonal() * V.transpose();
      std::vector<Vec3> x(4);
      double edge = 0;
      for (int i = 0; i < 4; ++i) x[i] = F * rest[i];
      for (const auto& [a, b] : kTetEdges) edge = std::max(edge, std::abs((x[b] - x[a]).norm() / (rest[b] - rest[a]).norm() - 1));
      closest = std::max(closest, top(x) / k0 / model.stiffness_growth(edge));
    }
    EXPECT_LE(closest, 1.0);
    std::printf("[ figure ] largest tangent growth / bound: %.3f\n", closest);
  }
}

TEST(LargeStrainGps, AModelFollowingACutEqualsOneBuiltOnTheCutMesh) {
  // A 10 x 2 x 2 cm bar of two materials, cut by a blade drawn down through it in ten sweeps, the
  // model following each (its backbone's lanes rewritten with the rest); then both at large strain.
  const auto live = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2));
  const Mat6 D = test::soft_tissue();
  std::vector<std::uint16_t> materials(live->tet_count(), 0);
  for (std::size_t e = 0; e < materials.size(); e += 3) materials[e] = 1;
  GpsModel model(live, {D, 2.0 * D}, materials, large_strain());
  std::vector<Vec3> x = live->nodes;
  for (auto& p : x) p = Vec3(1.001 * p.x(), p.y() - 0.002 * p.x(), p.z());
  MeshCutter cutter(*live);
  std::vector<double> memory;
  for (int k = 0; k < 10; ++k) {
    const double z0 = 0.03 - 0.004 * k, z1 = z0 - 0.004, xc = 0.0537;
    const CutChange c = cutter.cut({Vec3(xc, -0.01, z0), Vec3(xc, 0.03, z0), Vec3(xc, -0.01, z1), Vec3(xc, 0.03, z1)}, x, 0);
    for (const auto& n : c.new_nodes) x.push_back((1 - n.t) * x[static_cast<std::size_t>(n.a)] + n.t * x[static_cast<std::size_t>(n.b)]);
    model.follow_edit(c.edit(), memory);
    for (std::size_t e = materials.size(); e < live->tet_count(); ++e) materials.push_back(materials[static_cast<std::size_t>(c.origin[e])]);
  }
  ASSERT_GT(live->tet_count(), 240u);
  const GpsModel fresh(std::make_shared<TetMesh>(*live), {D, 2.0 * D}, materials, large_strain());
  for (auto& p : x) p = Vec3(1.2 * p.x(), p.y() - 0.2 * p.x(), 0.9 * p.z());  // then large strain
  const auto fa = forces(model, x), fb = forces(fresh, x);
  EXPECT_GT(largest(fb), 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(fa[i], fb[i]) << "node " << i;
}
