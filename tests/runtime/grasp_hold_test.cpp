// The grasper's hold against closed form: a ring of held nodes resists a twist of the tool with  // SPDX-License-Identifier: Apache-2.0
// torque -k N r^2 sin(theta) and no net force; a lift off-centre gives force -k d and the moment
// of that force about the tip; only the nodes within the grasp radius are held; the forces on the
// tissue are the opposite of the tool's; during a step each spring acts at the extension the step
// will end at.
#include "viscera/runtime/grasp_hold.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

using namespace viscera::runtime;

namespace {
constexpr double k = 100.0;  // N/m per node
const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
}  // namespace

TEST(GraspHold, TwistingTheToolIsResistedByTheRingItHolds) {
  const Vec3 tip(0.01, -0.02, 0.05);
  const double r = 0.004;
  const int n = 12;
  std::vector<Vec3> x;
  std::vector<std::int32_t> nodes;
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * std::numbers::pi * i / n;
    x.push_back(tip + r * Vec3(std::cos(phi), std::sin(phi), 0));
    nodes.push_back(i);
  }
  x.push_back(tip + Vec3(0.02, 0, 0));  // beyond the grasp radius: not held
  nodes.push_back(n);
  const GraspHold hold(tip, identity, nodes, x, 0.006, k);
  ASSERT_EQ(hold.size(), static_cast<std::size_t>(n));
  for (const double theta : {0.01, 0.2, -0.5}) {
    const Eigen::Quaterniond turned(Eigen::AngleAxisd(theta, Vec3::UnitZ()));
    std::vector<Vec3> f(x.size(), Vec3::Zero());
    std::vector<double> stiffness(x.size(), 0.0);
    const auto reaction = hold.apply(tip, turned, Vec3::Zero(), {x, {}, f, stiffness, {}, 0.0});
    EXPECT_NEAR(reaction.torque_on_tool.z(), -k * n * r * r * std::sin(theta), 1e-12) << theta;
    EXPECT_NEAR(reaction.torque_on_tool.head<2>().norm(), 0.0, 1e-15);
    EXPECT_NEAR(reaction.force_on_tool.norm(), 0.0, 1e-12);  // a symmetric ring: no net force
    Vec3 on_tissue = Vec3::Zero();
    for (const auto& fi : f) on_tissue += fi;
    EXPECT_NEAR((on_tissue + reaction.force_on_tool).norm(), 0.0, 1e-12);
    EXPECT_EQ(f[n], Vec3::Zero());
    EXPECT_EQ(stiffness[0], k);
    EXPECT_EQ(stiffness[n], 0.0);
  }
}

TEST(GraspHold, LiftingOffCentreGivesTheForceAndItsMomentAboutTheTip) {
  const Vec3 tip(0, 0, 0.1);
  const std::vector<Vec3> x{tip + Vec3(0.003, 0, 0)};
  const std::vector<std::int32_t> nodes{0};
  const GraspHold hold(tip, identity, nodes, x, 0.005, k);
  const double d = 0.01;
  const auto reaction = hold.query(tip + Vec3(0, 0, d), identity, x);  // the tissue stays
  EXPECT_NEAR((reaction.force_on_tool - Vec3(0, 0, -k * d)).norm(), 0.0, 1e-12);
  // Moment about the tip of -k d z at arm 0.003 x: -(0.003 x) x (k d z) = +0.003 k d y.
  EXPECT_NEAR((reaction.torque_on_tool - Vec3(0, 0.003 * k * d, 0)).norm(), 0.0, 1e-12);
}

TEST(GraspHold, TheHoldIsInTheToolsFrame) {
  // Grasped with the tool turned 90 degrees about x; turning it back moves the anchors with it.
  const Vec3 tip = Vec3::Zero();
  const std::vector<Vec3> x{Vec3(0, 0.002, 0)};
  const std::vector<std::int32_t> nodes{0};
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()));
  const GraspHold hold(tip, turned, nodes, x, 0.005, k);
  EXPECT_NEAR(hold.query(tip, turned, x).force_on_tool.norm(), 0.0, 1e-15);  // as grasped: slack
  // Back to identity: the anchor (tool frame (0, 0, -0.002)) is at (0, 0, -0.002) in the world.
  const auto back = hold.query(tip, identity, x);
  EXPECT_NEAR((back.force_on_tool - (-k * (Vec3(0, 0, -0.002) - x[0]))).norm(), 0.0, 1e-12);
}

TEST(GraspHold, DuringAStepEachSpringActsAtTheExtensionTheStepEndsAt) {
  // A node moving at v held by a tool moving at u: over a step dt the extension changes by
  // dt (u - v), and the spring acts at that end-of-step extension (backward Euler in the spring,
  // BoundaryConditions::FieldEvaluation), with its stiffness k reported.
  const Vec3 tip(0, 0, 0.1);
  const std::vector<Vec3> x{tip + Vec3(0.003, 0, 0)};
  const std::vector<std::int32_t> nodes{0};
  const GraspHold hold(tip, identity, nodes, x, 0.005, k);
  const Vec3 lift(0, 0.001, 0.01), u(0.05, 0, 0.2);
  const std::vector<Vec3> v{Vec3(-0.1, 0.3, 0)};
  for (const double dt : {0.0, 1e-4, 5e-4}) {
    std::vector<Vec3> f{Vec3::Zero()};
    std::vector<double> stiffness{0.0};
    const auto reaction = hold.apply(tip + lift, identity, u, {x, v, f, stiffness, {}, dt});
    const Vec3 expected = k * (lift + dt * (u - v[0]));
    EXPECT_NEAR((f[0] - expected).norm(), 0.0, 1e-12) << dt;
    EXPECT_NEAR((reaction.force_on_tool + expected).norm(), 0.0, 1e-12) << dt;
    EXPECT_EQ(stiffness[0], k);
  }
}
