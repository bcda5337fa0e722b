// The way out of an organ at any depth (server/runtime/surface_exit.hpp) against the closed form of  // SPDX-License-Identifier: Apache-2.0
// a box: inside exactly where the box is; a ray from inside crosses the face the geometry says, at
// its distance, and a tip that leaves along it ends one radius beyond that face, even where another
// face is nearer; the contact found from inside pushes along the crossed face's normal with the
// penalty spring at the tip's whole depth.
#include "viscera/runtime/surface_exit.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

using namespace viscera::runtime;

namespace {
const Vec3 kLo(-0.05, -0.04, -0.03), kHi(0.05, 0.04, 0.03);  // [m]

struct Box {
  viscera::tissue::TetMesh mesh = viscera::tissue::make_box_mesh(kLo, kHi, 10, 8, 6);
  std::shared_ptr<const ContactSurface> surface = make_contact_surface(viscera::tissue::extract_boundary(mesh).triangles, mesh.nodes);
};

/// Where the ray p + s d leaves the box (p inside): s, and the outward normal of the face it crosses.
std::pair<double, Vec3> box_exit(const Vec3& p, const Vec3& d) {
  double best = 1e9;
  Vec3 n = Vec3::Zero();
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0 && (kHi[a] - p[a]) / d[a] < best) best = (kHi[a] - p[a]) / d[a], n = Vec3::Unit(a);
    if (d[a] < 0 && (kLo[a] - p[a]) / d[a] < best) best = (kLo[a] - p[a]) / d[a], n = -Vec3::Unit(a);
  }
  return {best, n};
}
}  // namespace

TEST(SurfaceExit, InsideExactlyWhereTheBoxIs) {
  const Box box;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.07, 0.07);
  int inside = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const bool in_box = (p.array() > kLo.array()).all() && (p.array() < kHi.array()).all();
    ASSERT_EQ(inside_surface(*box.surface, box.mesh.nodes, p), in_box) << p.transpose();
    inside += in_box;
  }
  EXPECT_GT(inside, 300);  // both sides were tried
}

TEST(SurfaceExit, ATipDeepInsideLeavesTheWayItCameToOneRadiusOutside) {
  const Box box;
  const double radius = 0.006;
  const Vec3 up = Vec3::UnitZ(), slanted = Vec3(0.3, -0.2, 0.9).normalized(), sideways = -Vec3::UnitX();
  for (const auto& [p, d] : {std::pair{Vec3(0.0, 0.0, -0.02), up}, std::pair{Vec3(0.01, -0.005, 0.012), slanted},
                             std::pair{Vec3(-0.035, 0.02, -0.01), sideways}, std::pair{Vec3(0.003, 0.031, 0.0), up}}) {
    SCOPED_TRACE(p.transpose());
    const auto [s, n] = box_exit(p, d);
    const auto c = first_crossing(*box.surface, box.mesh.nodes, p, d);
    ASSERT_TRUE(c);
    EXPECT_NEAR(c->distance_m, s, 1e-12);
    EXPECT_NEAR((c->normal - n).norm(), 0.0, 1e-12);
    EXPECT_NEAR((c->point - (p + s * d)).norm(), 0.0, 1e-12);
    const auto out = way_out(*box.surface, box.mesh.nodes, p, d, radius);
    ASSERT_TRUE(out);
    EXPECT_NEAR((*out - (s + radius) * d).norm(), 0.0, 1e-12);
    EXPECT_FALSE(inside_surface(*box.surface, box.mesh.nodes, p + *out));
  }
  // 2 cm below the top and 1 cm above the bottom: out through the top when it came from above,
  // although the bottom is nearer.
  const auto from_above = way_out(*box.surface, box.mesh.nodes, Vec3(0, 0, -0.01), up, radius);
  ASSERT_TRUE(from_above);
  EXPECT_GT(from_above->z(), 0.0);
  EXPECT_FALSE(way_out(*box.surface, box.mesh.nodes, Vec3(0, 0, 0.05), up, radius));  // outside: nothing to do
}

TEST(SurfaceExit, TheContactFromInsideIsThePenaltySpringAtTheWholeDepth) {
  const Box box;
  const ProbeContact probe(box.surface, 0.006, 1000.0);  // reaches 2 cm below a face
  const Vec3 centre(0.0, 0.0, -0.005);  // 3.5 cm below the top, 2.5 cm above the bottom, 4 and 5 cm from the others
  EXPECT_FALSE(probe.query(centre, box.mesh.nodes).in_contact) << "the depth limit no longer hides the far faces";
  const ContactResult r = contact_from_inside(probe, box.mesh.nodes, centre, Vec3::UnitZ());  // pressed in from the top
  ASSERT_TRUE(r.in_contact);
  const double depth = 0.035 + 0.006;
  EXPECT_NEAR(r.depth_m, depth, 1e-12);
  EXPECT_NEAR((r.normal - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((r.force_on_tool - 1000.0 * depth * Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(r.stiffness[8], 1000.0, 1e-9);
  EXPECT_NEAR(r.stiffness[0], 0.0, 1e-9);
  EXPECT_FALSE(contact_from_inside(probe, box.mesh.nodes, Vec3(0, 0, 0.05), Vec3::UnitZ()).in_contact);
}
