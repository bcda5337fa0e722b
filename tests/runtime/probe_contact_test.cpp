// Probe contact against closed form on a flat, finely triangulated plate: one spring k at the  // SPDX-License-Identifier: Apache-2.0
// deepest penetration whatever the number of triangles under the tip, pushing out along the
// normal even when the tip centre has passed below the surface (no tunnelling), nothing out of
// reach, and the broad phase still finds the contact on a plate stretched well beyond rest.
#include "viscera/runtime/probe_contact.hpp"

#include <algorithm>
#include <memory>

#include <gtest/gtest.h>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

#include "flat_plate.hpp"

using namespace viscera::runtime;
using viscera::runtime::test::Plate;

TEST(ProbeContact, OneSpringAtTheDeepestPenetrationWhateverTheMeshing) {
  const double r = 0.006, k = 1000.0;
  for (const double h : {0.01, 0.002}) {  // 1 or 2 triangles under the tip, or dozens
    const Plate p(20, h);
    const ProbeContact contact(p.triangles, p.x, r, k);
    std::vector<Vec3> f(p.x.size(), Vec3::Zero());
    for (const double depth : {0.001, 0.004, 0.009, 0.015}) {  // the last two: centre below the surface
      std::fill(f.begin(), f.end(), Vec3::Zero());
      const ContactResult c = contact.apply(Vec3(0.0003, -0.0002, r - depth), Vec3::Zero(), {p.x, {}, f, {}, {}, 0.0});
      ASSERT_TRUE(c.in_contact) << "h " << h << " depth " << depth;
      EXPECT_NEAR(c.force_on_tool.z(), k * depth, 1e-9) << "h " << h << " depth " << depth;
      EXPECT_NEAR(c.force_on_tool.head<2>().norm(), 0.0, 1e-12);
      EXPECT_NEAR(c.depth_m, depth, 1e-12);
      Vec3 on_plate = Vec3::Zero();
      for (const auto& v : f) on_plate += v;
      EXPECT_NEAR((on_plate + c.force_on_tool).norm(), 0.0, 1e-9) << "action and reaction";
    }
    EXPECT_FALSE(contact.query(Vec3(0, 0, r + 1e-4), p.x).in_contact);  // just above
    EXPECT_FALSE(contact.query(Vec3(0, 0, -0.0201), p.x).in_contact);  // centre beyond the 2 cm depth limit
  }
}

TEST(ProbeContact, BroadPhaseFindsContactOnAStretchedSurface) {
  const double r = 0.006, k = 1000.0;
  const Plate rest(10, 0.01);
  const ProbeContact contact(rest.triangles, rest.x, r, k);
  std::vector<Vec3> stretched = rest.x;
  for (auto& v : stretched) v.head<2>() *= 2.5;  // every edge 2.5x its rest length
  for (const double xy : {0.0, 0.013, 0.041, 0.087}) {
    const ContactResult c = contact.query(Vec3(xy, -0.6 * xy, r - 0.002), stretched);
    ASSERT_TRUE(c.in_contact) << "tip over (" << xy << ", " << -0.6 * xy << ")";
    EXPECT_NEAR(c.force_on_tool.z(), k * 0.002, 1e-9);
  }
}

TEST(ProbeContact, HuntCrossleyDashpotGrowsWithDepthAndRateAndNeverPulls) {
  // Closed form: a plate moving up at u into a tool moving at w: the depth grows at u - w, the
  // normal force is k (d + dt (u - w)) + alpha k d (u - w) (the spring at the depth the step will
  // end at, and the dashpot), and never below zero when the surface leaves faster than the spring
  // pushes. Each node's damping bound is sqrt(3) alpha k d share w_node (the Gershgorin row sum):
  // the spring's predicted part is not a damping the integrator adds, it is backward Euler's.
  const double r = 0.006, k = 1000.0, alpha = 2.0, depth = 0.003, c = alpha * k * depth;
  const Plate p(20, 0.002);
  const ProbeContact contact(p.triangles, p.x, r, k, 0.02, alpha);
  const Vec3 tip(0.0003, -0.0002, r - depth);
  for (const double dt : {0.0, 4e-4})
    for (const double u : {0.0, 0.4, -0.7, -5.0})
      for (const double w : {0.0, -0.1}) {
        const std::vector<Vec3> v(p.x.size(), Vec3(0.01, 0.0, u));  // sliding along the plate changes nothing
        std::vector<Vec3> f(p.x.size(), Vec3::Zero());
        std::vector<double> stiffness(p.x.size(), 0.0), damping(p.x.size(), 0.0);
        const ContactResult res = contact.apply(tip, Vec3(0.02, 0, w), {p.x, v, f, stiffness, damping, dt});
        const double expected = std::max(0.0, k * (depth + dt * (u - w)) + c * (u - w));
        EXPECT_NEAR(res.force_on_tool.z(), expected, 1e-9) << "u " << u << " w " << w << " dt " << dt;
        Vec3 on_plate = Vec3::Zero();
        for (const auto& x : f) on_plate += x;
        EXPECT_NEAR((on_plate + res.force_on_tool).norm(), 0.0, 1e-9);
        double bound = 0, stiff = 0;
        for (std::size_t i = 0; i < damping.size(); ++i) {
          bound += damping[i];
          stiff += stiffness[i];
        }
        EXPECT_NEAR(bound, std::sqrt(3.0) * c, 1e-9);  // shares and barycentric weights sum to 1
        EXPECT_NEAR(stiff, std::sqrt(3.0) * k, 1e-9);
      }
  // Without velocities (the command thread's query) the contact is the spring alone.
  EXPECT_NEAR(contact.query(tip, p.x).force_on_tool.z(), k * depth, 1e-9);
}

// A piece cut free is still tissue under the probe: a 10 x 2 x 2 cm bar held at its left end is
// cut through at x = 5.4 cm, and a probe pressed 3 mm into the top of the free piece (no gravity)
// pushes it away, while the held piece does not move: no force crosses the cut.
TEST(ProbeContact, APieceCutFreeIsPushedByTheProbeAndTheHeldPieceFeelsNothing) {
  using namespace viscera::tissue;
  const auto mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2));
  MeshCutter cutter(*mesh);
  for (int i = 0; i < 20; ++i) {
    const double za = 0.03 - 0.002 * i, zb = za - 0.002, xc = 0.054;
    const std::vector<Vec3> x = mesh->nodes;
    cutter.cut({Vec3(xc, -0.01, za), Vec3(xc, 0.03, za), Vec3(xc, -0.01, zb), Vec3(xc, 0.03, zb)}, x, 0);
  }
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.3;
  const GpsModel gps(mesh, {elasticity_matrix(IsotropicElasticity{5e3, 0.45})}, {}, o);
  const ProbeContact probe(extract_boundary(*mesh).triangles, mesh->nodes, 0.005, 1000.0);
  const Vec3 tip(0.08, 0.01, 0.02 + 0.005 - 0.003);
  ContactResult first;
  BoundaryConditions bc;
  bc.fixed_nodes = nodes_in_box(*mesh, Box{Vec3(-1, -1, -1), Vec3(1e-9, 1, 1)});
  bc.force_field = [&](const BoundaryConditions::FieldEvaluation& e) {
    const ContactResult r = probe.apply(tip, Vec3::Zero(), e);
    if (!first.in_contact) first = r;
  };
  ExplicitIntegrator integrator(gps, std::vector<double>(mesh->tet_count(), 1000.0), bc);
  State s = State::at_rest(*mesh);
  const std::vector<double> m = integrator.masses();
  const auto free_centre_z = [&] {
    double mz = 0, mass = 0;
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (mesh->nodes[i].x() > 0.056) {
        mz += m[i] * s.x[i].z();
        mass += m[i];
      }
    return mz / mass;
  };
  const double z0 = free_centre_z();
  for (int k = 0; k < 100; ++k) integrator.step(s);
  ASSERT_TRUE(first.in_contact);
  EXPECT_NEAR(first.force_on_tool.z(), 1000.0 * 0.003, 1e-9);  // the penalty at 3 mm, on the tool
  EXPECT_LT(free_centre_z(), z0 - 1e-5);  // pushed down, away from the probe
  // The held piece moves by rounding only (its forces at rest are 1e-16 N, not 0), ten orders
  // below the pushed piece.
  double held = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (mesh->nodes[i].x() < 0.05) held = std::max(held, (s.x[i] - mesh->nodes[i]).norm());
  }
  EXPECT_LT(held, 1e-15);
}
