// The large-strain GPS with memory variables (docs/TISSUE.md, "Large strain"): its memory relaxes  // SPDX-License-Identifier: Apache-2.0
// the neo-Hookean backbone's second Piola-Kirchhoff stress. Against other code paths and closed
// forms: at small strain it is the GPS with memory (which is linear viscoelastic FE); a strain
// held at 30% compression relaxes as the linear relaxation modulus says (quasi-linear
// viscoelasticity); a loaded organ turned rigidly gives the turned forces; the tangent over a step
// is the forces' derivative with the memory loaded and bulk relaxing unlike shear; a model that
// follows a cut carries its memory as a fresh model loaded alike holds it.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

/// The liver's constant Q (4.8 over 0.01-10 Hz, three mechanisms); bulk relaxing alike, or not at all.
ViscoelasticSetup liver_q(bool bulk_relaxes) {
  ViscoelasticSpec spec;
  if (bulk_relaxes) spec.bulk_q = 4.8;
  return make_viscoelastic(test::soft_tissue(), spec);
}

GpsOptions options(const ViscoelasticSetup& ve, bool large) {
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.large_strain = large;
  o.mechanisms = ve.gps;
  return o;
}

/// One step of dt from `memory` (advanced in place): the forces.
std::vector<Vec3> step(const GpsModel& m, const std::vector<Vec3>& x, std::vector<double>& memory, double dt) {
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  std::vector<double> after(memory.size());
  m.add_forces(x, f, {memory, after, dt});
  memory.swap(after);
  return f;
}

double largest(const std::vector<Vec3>& f) {
  double s = 0;
  for (const auto& v : f) s = std::max(s, v.norm());
  return s;
}

double largest_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s = std::max(s, (a[i] - b[i]).norm());
  return s;
}

}  // namespace

TEST(LargeStrainMemory, AtSmallStrainItIsTheGpsWithMemory) {
  // The 1.5k liver shaken by a small random pattern at 2 Hz for 0.6 s in 1 ms steps (strains about
  // 1e-5): the forces of both models over the whole history, bulk relaxing or not.
  const auto mesh = test::liver2();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> pattern(mesh->node_count());
  for (auto& p : pattern) p = 2e-7 * Vec3(u(rng), u(rng), u(rng));
  for (const bool bulk_relaxes : {true, false}) {
    const ViscoelasticSetup ve = liver_q(bulk_relaxes);
    const GpsModel large(mesh, {ve.unrelaxed_elasticity}, {}, options(ve, true));
    const GpsModel gps(mesh, {ve.unrelaxed_elasticity}, {}, options(ve, false));
    std::vector<double> ml(large.memory_size(), 0.0), mg(gps.memory_size(), 0.0);
    double worst = 0, scale = 0;
    for (int k = 1; k <= 600; ++k) {
      const double a = std::sin(2 * M_PI * 2.0 * 1e-3 * k);
      std::vector<Vec3> x = mesh->nodes;
      for (std::size_t i = 0; i < x.size(); ++i) x[i] += a * pattern[i];
      const auto fl = step(large, x, ml, 1e-3), fg = step(gps, x, mg, 1e-3);
      worst = std::max(worst, largest_difference(fl, fg));
      scale = std::max(scale, largest(fg));
    }
    std::printf("[ figure ] small strain, bulk %s: large-strain GPS with memory vs GPS with memory, largest difference %.2e of the largest force\n",
                bulk_relaxes ? "relaxing" : "not relaxing", worst / scale);
    EXPECT_LT(worst, 1e-4 * scale) << (bulk_relaxes ? "bulk relaxing" : "bulk not relaxing");
  }
}

TEST(LargeStrainMemory, AStrainHeldAtThirtyPercentRelaxesAsTheLinearModulus) {
  // Quasi-linear viscoelasticity: after a (1 us) ramp to F = diag(0.7, 1.2, 1.2), held, every
  // force is the instantaneous one times G(t) / G(0) of the mechanisms (closed form,
  // StandardLinearSolids), to the ramp's O(w dt) when shear and bulk relax alike.
  const ViscoelasticSetup ve = liver_q(true);
  const auto mesh = test::single_tet_mesh({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.005, 0.00866, 0), Vec3(0.005, 0.00289, 0.00816)});
  const GpsModel model(mesh, {ve.unrelaxed_elasticity}, {}, options(ve, true));
  std::vector<Vec3> x = mesh->nodes;
  for (auto& p : x) p = Vec3(0.7 * p.x(), 1.2 * p.y(), 1.2 * p.z());
  std::vector<double> memory(model.memory_size(), 0.0);
  const auto f0 = step(model, x, memory, 1e-6);
  const StandardLinearSolids& g = ve.shear_fit.solids;
  double worst = 0, t = 1e-6;
  for (int k = 0; k < 400; ++k) {
    const double dt = 0.02;
    const auto f = step(model, x, memory, dt);
    t += dt;
    const double r = g.relaxation_modulus(t) / g.unrelaxed_modulus_pa;
    for (std::size_t i = 0; i < 4; ++i) worst = std::max(worst, (f[i] - r * f0[i]).norm() / largest(f0));
  }
  std::printf("[ figure ] 30%% compression held 8 s: forces against G(t)/G(0) times the instantaneous ones, largest difference %.2e of the force\n",
              worst);
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(g.relaxation_modulus(t) / g.unrelaxed_modulus_pa, 0.8) << "the test must see relaxation";
}

TEST(LargeStrainMemory, ALoadedOrganTurnedRigidlyGivesTheTurnedForces) {
  const ViscoelasticSetup ve = liver_q(false);
  const auto mesh = test::liver2();
  const GpsModel model(mesh, {ve.unrelaxed_elasticity}, {}, options(ve, true));
  std::vector<Vec3> x = mesh->nodes;
  for (auto& p : x) p = Vec3(1.1 * p.x(), p.y() + 0.2 * p.z(), 0.8 * p.z());
  std::vector<double> memory(model.memory_size(), 0.0);
  for (int k = 0; k < 50; ++k) step(model, x, memory, 1e-2);
  std::mt19937_64 rng(9);
  const Mat3 R = test::random_rotation(rng);
  std::vector<Vec3> turned = x;
  for (auto& p : turned) p = R * p + Vec3(0.05, -0.1, 0.2);
  std::vector<double> copy = memory;
  const auto f = step(model, x, memory, 1e-3), ft = step(model, turned, copy, 1e-3);
  double worst = 0;
  for (std::size_t i = 0; i < f.size(); ++i) worst = std::max(worst, (ft[i] - R * f[i]).norm());
  EXPECT_LT(worst, 1e-9 * largest(f));
  EXPECT_GT(largest(f), 0.0);
}

TEST(LargeStrainMemory, TheTangentOverAStepIsTheForcesDerivativeWithTheMemoryLoaded) {
  std::mt19937_64 rng(37);
  const double dt = 1e-3;
  for (const bool bulk_relaxes : {true, false}) {
    ViscoelasticSetup ve = liver_q(bulk_relaxes);
    if (bulk_relaxes) ve.gps.viscous.kelvin_voigt_time_s = 10 * dt;  // taken only where the bulk relaxes as the shear
    const auto rest = test::random_tet(rng);
    const GpsModel model(test::single_tet_mesh(rest), {ve.unrelaxed_elasticity}, {}, options(ve, true));
    std::vector<double> memory(model.memory_size(), 0.0);
    std::vector<Vec3> x(rest.begin(), rest.end());
    for (auto& p : x) p = 0.7 * p + 0.002 * Vec3(std::uniform_real_distribution<double>(-1, 1)(rng), 0.3, -0.2);
    for (int k = 0; k < 20; ++k) step(model, x, memory, 0.05);
    for (int i = 0; i < 4; ++i) x[i] = rest[i] + 0.8 * (x[i] - rest[i]) + Vec3(0.0004 * i, -0.0003, 0.0002 * i);
    const Mat12 K = model.element_tangent(x, 0, dt, memory);
    Mat12 fd;
    const double h = 1e-8;
    for (int c = 0; c < 12; ++c) {
      std::vector<Vec3> xp = x, xm = x;
      xp[c / 3][c % 3] += h;
      xm[c / 3][c % 3] -= h;
      std::vector<double> a = memory, b = memory;
      const auto fp = step(model, xp, a, dt), fm = step(model, xm, b, dt);
      for (int r = 0; r < 12; ++r) fd(r, c) = -(fp[r / 3][r % 3] - fm[r / 3][r % 3]) / (2 * h);
    }
    EXPECT_LT((K - fd).norm(), 1e-5 * fd.norm()) << (bulk_relaxes ? "bulk relaxing" : "bulk not relaxing");
  }
}

TEST(LargeStrainMemory, AModelFollowingACutCarriesTheMemoryAFreshModelLoadedAlikeHolds) {
  // A homogeneous deformation held 0.5 s gives every element the same stress and memory: after a
  // cut, the pieces must hold their parents', as a model built on the cut mesh and held alike.
  const ViscoelasticSetup ve = liver_q(false);
  const auto live = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2));
  GpsModel model(live, {ve.unrelaxed_elasticity}, {}, options(ve, true));
  const auto deform = [](std::vector<Vec3> x) {
    for (auto& p : x) p = Vec3(0.8 * p.x() + 0.1 * p.y(), 1.1 * p.y(), 1.1 * p.z());
    return x;
  };
  std::vector<Vec3> x = deform(live->nodes);
  std::vector<double> memory(model.memory_size(), 0.0);
  for (int k = 0; k < 50; ++k) step(model, x, memory, 1e-2);
  MeshCutter cutter(*live);
  for (int k = 0; k < 10; ++k) {
    const double z0 = 0.03 - 0.004 * k, z1 = z0 - 0.004, xc = 0.0537;
    const std::vector<Vec3> now = live->nodes;  // cut at rest: the cutter grows the mesh's nodes
    const CutChange c = cutter.cut({Vec3(xc, -0.01, z0), Vec3(xc, 0.03, z0), Vec3(xc, -0.01, z1), Vec3(xc, 0.03, z1)}, now, 0);
    model.follow_edit(c.edit(), memory);
  }
  ASSERT_GT(live->tet_count(), 240u);
  x = deform(live->nodes);
  const GpsModel fresh(std::make_shared<TetMesh>(*live), {ve.unrelaxed_elasticity}, {}, options(ve, true));
  std::vector<double> fresh_memory(fresh.memory_size(), 0.0);
  for (int k = 0; k < 50; ++k) step(fresh, x, fresh_memory, 1e-2);
  const auto fa = step(model, x, memory, 1e-3), fb = step(fresh, x, fresh_memory, 1e-3);
  EXPECT_LT(largest_difference(fa, fb), 1e-9 * largest(fb));
  EXPECT_GT(largest(fb), 0.0);
}
