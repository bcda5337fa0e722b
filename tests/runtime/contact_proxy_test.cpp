// The contact proxy against closed forms: on a rigid plate the proxy stays on the surface at any  // SPDX-License-Identifier: Apache-2.0
// depth of the goal (where the penalty contact lets go past its depth limit), the force is k
// times the goal's depth, and Coulomb's cone holds exactly (stick below mu_s, slide at mu_k); on
// a faceted sphere the force changes smoothly where the penalty contact's jumps at every edge;
// on a deforming block of tissue the lateral force of a steady slide is mu times the normal,
// tissue under a stuck tip moves with it, and a press to 70% of the block's height never lets the
// proxy into the tissue (measured by the penalty contact's own geometry, another code path).
#include "viscera/runtime/contact_proxy.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <gtest/gtest.h>

#include "viscera/runtime/surface_exit.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

#include "flat_plate.hpp"

using namespace viscera::runtime;
using viscera::runtime::test::Plate;
using viscera::tissue::BoundaryConditions;
using viscera::tissue::Triangle;

namespace {
/// A sphere of radius R triangulated by latitude and longitude (poles excluded: a band), outward normals.
struct FacetedSphere {
  std::vector<Vec3> x;
  std::vector<Triangle> triangles;
  FacetedSphere(double R, int around, int rings) {
    for (int j = 0; j <= rings; ++j) {
      const double theta = std::numbers::pi * (0.15 + 0.7 * j / rings);
      for (int i = 0; i < around; ++i) {
        const double phi = 2 * std::numbers::pi * i / around;
        x.emplace_back(R * std::sin(theta) * std::cos(phi), R * std::sin(theta) * std::sin(phi), R * std::cos(theta));
      }
    }
    const auto id = [around](int i, int j) { return static_cast<std::int32_t>(j * around + (i % around)); };
    for (int j = 0; j < rings; ++j)
      for (int i = 0; i < around; ++i) {
        triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
        triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
      }
  }
};

ContactProxyParameters parameters(double r, double k, double mu_s = 0, double mu_k = 0) {
  ContactProxyParameters p;
  p.tip_radius_m = r;
  p.stiffness_n_per_m = k;
  p.friction = {mu_s, mu_k};
  p.force_limit_n = 1000;
  return p;
}

/// How far a sphere overlaps the tissue, by brute force: its radius less the distance from its
/// centre to the nearest point of any surface triangle, or plus it for a centre inside.
double sphere_overlap(const ContactSurface& s, std::span<const Vec3> x, const Vec3& c, double radius) {
  double nearest = INFINITY;
  for (const auto& t : s.triangles) {
    Vec3 w;
    nearest = std::min(nearest, (c - closest_point_on_triangle(c, x[t[0]], x[t[1]], x[t[2]], &w)).norm());
  }
  return inside_surface(s, x, c) ? radius + nearest : radius - nearest;
}

ContactResult at(const ContactProxy& proxy, const Vec3& goal, std::span<const Vec3> x) {
  return proxy.apply(goal, Vec3::Zero(), {x, {}, {}, {}, {}, 0.0});
}
}  // namespace

TEST(ContactProxy, StaysOnARigidSurfaceAtAnyDepthOfTheGoal) {
  const double r = 0.006, k = 1000.0;
  const Plate plate(30, 0.002);
  const auto surface = make_contact_surface(plate.triangles, plate.x);
  ContactProxy proxy(surface, parameters(r, k));
  const ProbeContact penalty(surface, r, k);
  Vec3 goal(0.0011, -0.0007, r + 0.001);
  while (goal.z() > r - 0.06) {  // 1 um steps to the first touch, then 0.5 mm ticks to 60 mm deep
    goal.z() -= proxy.anchored() ? 5e-4 : 1e-6;
    proxy.track(goal, plate.x, 1e-3);
    if (!proxy.anchored()) continue;
    const double depth = r - goal.z();
    const ContactResult c = at(proxy, goal, plate.x);
    if (depth < 1e-5) continue;  // the first touch: no force yet
    ASSERT_TRUE(c.in_contact) << "depth " << depth;
    EXPECT_NEAR(c.force_on_tool.z(), k * depth, k * 2e-6) << "depth " << depth;
    EXPECT_NEAR(c.force_on_tool.head<2>().norm(), 0.0, 1e-12);
    const Vec3 centre = proxy.centre(goal, plate.x);
    EXPECT_NEAR(centre.z(), r, 2e-6) << "on the surface";
    EXPECT_NEAR((centre - goal).head<2>().norm(), 0.0, 1e-12) << "right above the goal";
    if (depth > 0.0205 + r) {
      EXPECT_FALSE(penalty.query(goal, plate.x).in_contact) << "the penalty contact has let go at " << depth;
    }
  }
  goal.z() = r + 1e-4;  // lifted out: it lets go
  proxy.track(goal, plate.x, 1e-3);
  EXPECT_FALSE(proxy.anchored());
  EXPECT_FALSE(at(proxy, goal, plate.x).in_contact);
}

TEST(ContactProxy, CoulombConeOnARigidPlateSticksBelowStaticAndSlidesAtKinetic) {
  const double r = 0.006, k = 1000.0, mu_s = 0.4, mu_k = 0.3, depth = 0.003;
  const Plate plate(40, 0.002);
  ContactProxy proxy(make_contact_surface(plate.triangles, plate.x), parameters(r, k, mu_s, mu_k));
  Vec3 goal(0.0003, 0.0002, r + 1e-4);
  while (goal.z() > r - depth + 1e-12) {
    goal.z() = std::max(r - depth, goal.z() - 1e-6);
    proxy.track(goal, plate.x, 1e-3);
  }
  ASSERT_TRUE(proxy.anchored());
  const Vec3 start = proxy.centre(goal, plate.x);
  // Slide in +x at 2 cm/s (20 um a tick) for 12 mm.
  for (int tick = 1; tick <= 600; ++tick) {
    goal.x() += 2e-5;
    proxy.track(goal, plate.x, 1e-3);
    const ContactResult c = at(proxy, goal, plate.x);
    ASSERT_TRUE(c.in_contact);
    const double fn = c.force_on_tool.z(), ft = -c.force_on_tool.x();
    const double shift = goal.x() - start.x();
    EXPECT_NEAR(fn, k * depth, 1e-9);
    if (shift <= mu_s * depth - 1e-9) {  // within the static cone: stuck where it touched
      EXPECT_FALSE(proxy.sliding()) << "shift " << shift;
      EXPECT_EQ(c.friction_mu, mu_s) << "the local model's cone: static while stuck";
      EXPECT_NEAR(proxy.centre(goal, plate.x).x(), start.x(), 1e-12);
      EXPECT_NEAR(ft, k * shift, 1e-9);
    } else {  // sliding: the proxy trails the goal by mu_k depth, the force on the kinetic cone
      EXPECT_TRUE(proxy.sliding()) << "shift " << shift;
      EXPECT_EQ(c.friction_mu, mu_k);
      EXPECT_NEAR(ft / fn, mu_k, 1e-9) << "shift " << shift;
      EXPECT_NEAR(goal.x() - proxy.centre(goal, plate.x).x(), mu_k * depth, 1e-9);
    }
  }
  // Reversing: it sticks again, and the force falls through zero before sliding the other way.
  const double trailing = proxy.centre(goal, plate.x).x();
  goal.x() -= 0.5 * mu_k * depth;
  proxy.track(goal, plate.x, 1e-3);
  EXPECT_FALSE(proxy.sliding());
  EXPECT_NEAR(proxy.centre(goal, plate.x).x(), trailing, 1e-12);
  EXPECT_NEAR(-at(proxy, goal, plate.x).force_on_tool.x(), 0.5 * mu_k * k * depth, 1e-9);
}

TEST(ContactProxy, SmoothNormalsMakeASlideOverFacetsContinuous) {
  // A goal kept 3 mm inside a sphere of 5 cm radius faceted every 15 degrees, slid around its
  // equator at 2 cm/s: the penalty contact's force turns by the facets' angle at each edge, the
  // proxy's (normals interpolated from the vertices) turns with the shape.
  const double R = 0.05, r = 0.006, k = 1000.0, depth = 0.003;
  const FacetedSphere sphere(R, 24, 8);
  const auto surface = make_contact_surface(sphere.triangles, sphere.x);
  ContactProxy proxy(surface, parameters(r, k));
  const ProbeContact penalty(surface, r, k);
  const auto goal_at = [&](double phi, double radial) { return Vec3(radial * std::cos(phi), radial * std::sin(phi), 0.0); };
  for (double radial = R + r + 1e-4; radial > R + r - depth; radial -= 1e-6) proxy.track(goal_at(0.0, radial), sphere.x, 1e-3);
  ASSERT_TRUE(proxy.anchored());
  double largest_step_proxy = 0, largest_step_penalty = 0, mean = 0;
  Vec3 last_proxy = at(proxy, goal_at(0.0, R + r - depth), sphere.x).force_on_tool;
  Vec3 last_penalty = penalty.query(goal_at(0.0, R + r - depth), sphere.x).force_on_tool;
  const int ticks = 2000;  // 4 cm
  for (int tick = 1; tick <= ticks; ++tick) {
    const Vec3 goal = goal_at(2e-5 * tick / R, R + r - depth);
    proxy.track(goal, sphere.x, 1e-3);
    const Vec3 f = at(proxy, goal, sphere.x).force_on_tool, g = penalty.query(goal, sphere.x).force_on_tool;
    ASSERT_GT(f.norm(), 0.0);
    largest_step_proxy = std::max(largest_step_proxy, (f - last_proxy).norm());
    largest_step_penalty = std::max(largest_step_penalty, (g - last_penalty).norm());
    mean += f.norm() / ticks;
    last_proxy = f;
    last_penalty = g;
  }
  std::printf("largest 1 ms change of the force: proxy %.3f%%, penalty contact %.3f%% of the mean %.3f N\n", 100 * largest_step_proxy / mean,
              100 * largest_step_penalty / mean, mean);
  EXPECT_LT(largest_step_proxy, 0.02 * mean);
}

namespace {
/// A 6 x 6 x 2 cm block of soft tissue (E 5 kPa, nu 0.45) fixed at its base, pressed by a proxy.
struct Block {
  std::shared_ptr<viscera::tissue::TetMesh> mesh;
  std::unique_ptr<viscera::tissue::GpsModel> model;
  std::unique_ptr<viscera::tissue::ExplicitIntegrator> integrator;
  std::shared_ptr<const ContactSurface> surface;
  viscera::tissue::State state;
  ContactResult last;
  Vec3 goal = Vec3::Zero(), goal_velocity = Vec3::Zero();
  Block() {
    using namespace viscera::tissue;
    mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(-0.03, -0.03, 0), Vec3(0.03, 0.03, 0.02), 12, 12, 4));
    GpsOptions o;
    o.variant = GpsVariant::energy_consistent;
    o.volume_stiffness_fraction = 0.5;
    model = std::make_unique<GpsModel>(mesh, std::vector<Mat6>{elasticity_matrix(IsotropicElasticity{5e3, 0.45})}, std::vector<std::uint16_t>{}, o);
    surface = make_contact_surface(extract_boundary(*mesh).triangles, mesh->nodes);
    state = State::at_rest(*mesh);
  }
  void attach(ContactProxy* proxy) {
    using namespace viscera::tissue;
    BoundaryConditions bc;
    bc.fixed_nodes = nodes_in_box(*mesh, Box{Vec3(-1, -1, -1), Vec3(1, 1, 1e-9)});
    bc.force_field = [this, proxy](const BoundaryConditions::FieldEvaluation& e) { last = proxy->apply(goal, goal_velocity, e); };
    ExplicitOptions eo;
    eo.mass_damping_per_s = 200;  // damped as tissue is: an undamped block rings under a sliding tip (stick-slip)
    integrator = std::make_unique<ExplicitIntegrator>(*model, std::vector<double>(mesh->tet_count(), 1000.0), bc, eo);
  }
  void tick(ContactProxy& proxy, const Vec3& next_goal) {
    goal_velocity = (next_goal - goal) / 1e-3;
    goal = next_goal;
    proxy.track(goal, state.x, 1e-3);
    integrator->advance(state, 1e-3);
  }
};
}  // namespace

TEST(ContactProxy, SteadySlideOnTissueGivesMuTimesTheNormalForce) {
  const double r = 0.006, k = 1000.0, mu = 0.3;
  Block b;
  ContactProxy proxy(b.surface, parameters(r, k, mu, mu));
  b.attach(&proxy);
  Vec3 goal(-0.01, 0.0, 0.02 + r + 1e-4);
  while (goal.z() > 0.02 + r - 0.008) {
    b.tick(proxy, goal += Vec3(0, 0, -1e-5));  // pressed 8 mm at 1 cm/s
  }
  for (int t = 0; t < 200; ++t) b.tick(proxy, goal);  // settle
  double lateral = 0, normal = 0;
  for (int t = 0; t < 1000; ++t) {  // 2 cm at 2 cm/s; the ratio over the last centimetre
    b.tick(proxy, goal += Vec3(2e-5, 0, 0));
    ASSERT_TRUE(b.last.in_contact);
    if (t >= 500) {
      lateral += -b.last.force_on_tool.x();
      normal += b.last.force_on_tool.z();
    }
  }
  std::printf("steady slide on the block at mu = %.2f: lateral / normal %.4f (normal %.3f N)\n", mu, lateral / normal, normal / 500);
  EXPECT_NEAR(lateral / normal, mu, 0.03);
  EXPECT_TRUE(proxy.sliding());
}

TEST(ContactProxy, TissueUnderAStuckTipMovesWithItAndSlipsBeyondTheCone) {
  const double r = 0.006, k = 1000.0, mu_s = 0.5, mu_k = 0.4;
  Block b;
  ContactProxy proxy(b.surface, parameters(r, k, mu_s, mu_k));
  b.attach(&proxy);
  Vec3 goal(0.0, 0.0, 0.02 + r + 1e-4);
  while (goal.z() > 0.02 + r - 0.008) b.tick(proxy, goal += Vec3(0, 0, -1e-5));
  for (int t = 0; t < 200; ++t) b.tick(proxy, goal);
  const Vec3 touched = b.last.point;
  // 2 mm sideways in 0.2 s, then held: the tissue comes along (stick), the proxy's point moves by
  // the shift less the coupling's stretch, F_t / k.
  for (int t = 0; t < 200; ++t) b.tick(proxy, goal += Vec3(1e-5, 0, 0));
  for (int t = 0; t < 300; ++t) b.tick(proxy, goal);
  ASSERT_TRUE(b.last.in_contact);
  EXPECT_FALSE(proxy.sliding());
  const double ft = -b.last.force_on_tool.x(), fn = b.last.force_on_tool.z();
  std::printf("stuck: tissue under the tip moved %.3f mm of the tool's 2 mm, F_t / F_n %.3f\n", 1e3 * (b.last.point.x() - touched.x()), ft / fn);
  EXPECT_LT(ft, mu_s * fn);
  EXPECT_GT(b.last.point.x() - touched.x(), 0.5e-3) << "the tissue under the tip came along";
  EXPECT_NEAR(b.last.point.x() - touched.x(), 2e-3 - ft / k, 0.1e-3);
  // 15 mm more: past the static cone it slides, on the kinetic cone.
  bool slid = false;
  for (int t = 0; t < 750; ++t) {
    b.tick(proxy, goal += Vec3(2e-5, 0, 0));
    slid = slid || proxy.sliding();
  }
  EXPECT_TRUE(slid);
  EXPECT_NEAR(-b.last.force_on_tool.x() / b.last.force_on_tool.z(), mu_k, 0.05);
}

TEST(ContactProxy, APressTo70PercentOfTheBlockHoldsTheProxyOnTheSurface) {
  // The goal goes 14 mm into a 20 mm block at 1 cm/s: the force never falls back (the tool neither
  // slides off nor passes through), the proxy's point stays on the deformed surface and its centre
  // outside the tissue (measured by brute force over every triangle and a ray's parity: another
  // code path). How far its sphere overlaps the dent's walls is printed: the force acts on a
  // kernel of the tip's radius, not as a sphere's pressure, so the dent is narrower than the tip.
  const double r = 0.006, k = 1000.0;
  Block b;
  auto p = parameters(r, k, 0.15, 0.1);
  p.force_limit_n = 15;
  ContactProxy proxy(b.surface, p);
  b.attach(&proxy);
  Vec3 goal(0.002, -0.001, 0.02 + r + 1e-4);
  double peak = 0, worst_fall = 0, worst_overlap = 0, worst_off_surface = 0, touched_z = NAN;
  while (goal.z() > 0.02 + r - 0.014) {
    b.tick(proxy, goal += Vec3(0, 0, -1e-5));
    if (std::isnan(touched_z) && proxy.anchored()) touched_z = goal.z();
    if (std::isnan(touched_z) || goal.z() > touched_z - 1e-3) continue;  // from 1 mm past the first touch
    ASSERT_TRUE(b.last.in_contact);
    const double f = b.last.force_on_tool.norm();
    peak = std::max(peak, f);
    worst_fall = std::max(worst_fall, (peak - f) / peak);
    const Vec3 centre = proxy.centre(goal, b.state.x);
    ASSERT_FALSE(inside_surface(*b.surface, b.state.x, centre)) << "the proxy's centre entered the tissue at goal z " << goal.z();
    worst_overlap = std::max(worst_overlap, sphere_overlap(*b.surface, b.state.x, centre, r));
    worst_off_surface = std::max(worst_off_surface, std::abs(r - sphere_overlap(*b.surface, b.state.x, b.last.point, r)));
  }
  std::printf(
      "pressed 14 mm: peak %.3f N, largest fall below the running peak %.2f%%, proxy's point off the surface by %.3f mm at most, "
      "its sphere overlapping the dent's walls by %.3f mm at most\n",
      peak, 100 * worst_fall, 1e3 * worst_off_surface, 1e3 * worst_overlap);
  EXPECT_GT(peak, 1.0);
  EXPECT_LT(worst_fall, 0.10);
  EXPECT_LT(worst_off_surface, 0.5e-3);  // the figure for the proxy's penetration
}
