// The implicit integrator (CHOLMOD) following a cut in place (docs/CUTTING.md, "The implicit  // SPDX-License-Identifier: Apache-2.0
// path"): against an integrator built afresh on the cut mesh from the same state, the pattern
// analysed once per edit and never per step, and every node of the cut organ stiff.
#include <algorithm>
#include <iostream>
#include <memory>

#include <gtest/gtest.h>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

#include "cutting_support.hpp"
#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

GpsModel bar_model(std::shared_ptr<TetMesh> mesh) {
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.3;
  return GpsModel(std::move(mesh), {test::soft_tissue()}, {}, o);
}

BoundaryConditions held_at_left(const TetMesh& m) {
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  bc.fixed_nodes = nodes_in_box(m, Box{Vec3(-1, -1, -1), Vec3(1e-9, 1, 1)});
  return bc;
}

TEST(ImplicitCutting, TheImplicitIntegratorFollowsACutInPlaceAsOneBuiltAfreshOnTheCutMesh) {
  // A 10 x 2 x 2 cm bar held at its left end sags under gravity; a blade notches it from the top
  // down to mid-height at x = 5.4 cm while it moves, the model and the implicit integrator
  // following each sweep in place; then both it and an integrator built afresh on the cut mesh,
  // from the same state, take ten backward Euler steps.
  const auto live = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2));
  GpsModel model = bar_model(live);
  const double density = 1000.0;
  ImplicitOptions io;
  io.dt_s = 1e-3;
  ImplicitIntegrator implicit(model, std::vector<double>(live->tet_count(), density), held_at_left(*live), io);
  State s = State::at_rest(*live);
  for (int k = 0; k < 3; ++k) implicit.step(s);
  EXPECT_EQ(implicit.pattern_analyses(), 1);
  MeshCutter cutter(*live);
  std::vector<double> no_memory;
  int edits = 0;
  for (int k = 0; k < 8; ++k) {  // from 5 mm above the top to mid-height, 2 mm a sweep
    const double z0 = 0.025 - 0.002 * k, z1 = z0 - 0.002, xc = 0.054;
    const CutChange c = cutter.cut({Vec3(xc, -0.01, z0), Vec3(xc, 0.03, z0), Vec3(xc, -0.01, z1), Vec3(xc, 0.03, z1)}, s.x, 0);
    if (!c.topology_changed()) continue;
    ++edits;
    model.follow_edit(c.edit(), no_memory);
    implicit.follow_edit(c.edit(), s);
  }
  ASSERT_GE(edits, 3);
  EXPECT_EQ(implicit.pattern_analyses(), 1 + edits);  // once per edit followed
  ASSERT_EQ(s.x.size(), live->node_count());

  // Afresh: the cut mesh copied, the same material, the left end held, the state as it stands.
  const auto copy = std::make_shared<TetMesh>(*live);
  const GpsModel fresh_model = bar_model(copy);
  ImplicitIntegrator fresh(fresh_model, std::vector<double>(copy->tet_count(), density), held_at_left(*copy), io);
  State t = s;
  for (std::size_t i = 0; i < implicit.masses().size(); ++i) ASSERT_EQ(implicit.masses()[i], fresh.masses()[i]) << "node " << i;
  double worst = 0;
  for (int k = 0; k < 10; ++k) {
    const NewtonReport a = implicit.step(s), b = fresh.step(t);
    ASSERT_TRUE(a.converged && b.converged) << "step " << k;
    for (std::size_t i = 0; i < s.x.size(); ++i) worst = std::max(worst, (s.x[i] - t.x[i]).norm());
  }
  EXPECT_EQ(implicit.pattern_analyses(), 1 + edits);  // the steps refactorised numerically only
  EXPECT_LE(worst, 1e-15);  // the same pattern, masses and forces: the same steps to rounding
  // Held at one end and notched half through, the cut bar is one stiff body: its static
  // stiffness is positive definite, so no node was left without stiffness.
  EXPECT_TRUE(implicit.factorize_stiffness(s.x));
  double sag = 0;
  for (const Vec3& p : s.x) sag = std::min(sag, p.z());
  std::cout << "[ figure ] implicit path following " << edits << " edits in place: " << live->tet_count() << " tetrahedra, "
            << implicit.pattern_analyses() << " pattern analyses, largest difference from an integrator built afresh over 10 steps " << worst
            << " m (the bar's lowest point " << 1e3 * sag << " mm)\n";
}

TEST(ImplicitCutting, ANewNodeIsHeldAsBothItsEndsAre) {
  BoundaryConditions bc;
  bc.fixed_nodes = {0, 1};
  bc.fixed_axes = {{0, 2}, {1, 2}, {2, 2}, {3, 1}};
  bc.prescribed.push_back({{4, 5}, [](const Vec3& r, double) { return r; }});
  bc.nodal_forces.assign(6, Vec3(1, 0, 0));
  // 6: on 0-1 (both fixed); 7: on 0-2 (z held at both); 8: on 2-3 (no common axis); 9: on 4-5
  // (prescribed); 10: a copy of 6 (made in the same edit); 11: on 6-3 (6 fixed, 3 holds y only).
  const std::vector<NewNodeEnds> ends = {{0, 1}, {0, 2}, {2, 3}, {4, 5}, {6, 6}, {6, 3}};
  extend_constraints(bc, ends, 6);
  EXPECT_EQ(bc.fixed_nodes, (std::vector<std::int32_t>{0, 1, 6, 10}));
  const auto holds = [&](std::int32_t n, int axis) {
    return std::any_of(bc.fixed_axes.begin(), bc.fixed_axes.end(), [&](const AxisConstraint& c) { return c.node == n && c.axis == axis; });
  };
  EXPECT_TRUE(holds(7, 2));
  EXPECT_FALSE(holds(8, 1) || holds(8, 2));
  EXPECT_TRUE(holds(11, 1));  // 6 holds every axis (a fixed node), 3 holds y: their edge's node holds y
  EXPECT_FALSE(holds(11, 0) || holds(11, 2));
  EXPECT_EQ(bc.prescribed[0].nodes, (std::vector<std::int32_t>{4, 5, 9}));
  ASSERT_EQ(bc.nodal_forces.size(), 12u);
  EXPECT_EQ(bc.nodal_forces[11], Vec3::Zero());
  const auto mask = bc.constrained_mask(12);
  EXPECT_EQ(mask[3 * 6 + 0] + mask[3 * 6 + 1] + mask[3 * 6 + 2], 3);
  EXPECT_EQ(mask[3 * 7 + 2], 1);
  EXPECT_EQ(mask[3 * 8 + 0] + mask[3 * 8 + 1] + mask[3 * 8 + 2], 0);
}

}  // namespace
