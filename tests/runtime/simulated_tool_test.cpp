// The simulated tool against its definition: it follows the command at most at the speed limit,  // SPDX-License-Identifier: Apache-2.0
// a grasper grasps below 0.1 rad and lets go above 0.2 rad (not between), and a contact ends only
// after 50 ms of simulated time without touching.
#include "viscera/runtime/simulated_tool.hpp"

#include <gtest/gtest.h>

namespace viscera::runtime {
namespace {

protocol::Command at(double z, double jaw = 0.5) {
  protocol::Command c;
  c.tip_position = {0, 0, z};
  c.jaw_opening = jaw;
  return c;
}

TEST(SimulatedTool, FollowsTheCommandAtMostAtTheSpeedLimit) {
  SimulatedTool tool({1, InstrumentKind::probe});
  tool.begin_tick(true, 11, at(0.0));  // becoming active: starts at the commanded tip
  EXPECT_EQ(tool.position().z(), 0.0);
  tool.begin_tick(true, 11, at(-0.01));  // 1 cm away; 0.5 m/s x 1 ms = 0.5 mm per tick
  for (int k = 1; k <= 20; ++k) {
    tool.move(1e-3, 0.5);
    EXPECT_NEAR(tool.position().z(), -0.0005 * k, 1e-15) << "tick " << k;
    EXPECT_NEAR(tool.velocity().z(), -0.5, 1e-9);
  }
  tool.move(1e-3, 0.5);  // arrived: stays, at rest
  EXPECT_NEAR(tool.position().z(), -0.01, 1e-15);
  EXPECT_EQ(tool.velocity().z(), 0.0);
  // Inactive (released): does not move; active again, it starts where its command is.
  tool.begin_tick(false, 0, at(0.3));
  tool.move(1e-3, 0.5);
  EXPECT_NEAR(tool.position().z(), -0.01, 1e-15);
  tool.begin_tick(true, 12, at(0.3));
  EXPECT_EQ(tool.position().z(), 0.3);
}

TEST(SimulatedTool, TheJawsGraspBelowTheFirstThresholdAndLetGoAboveTheSecond) {
  SimulatedTool grasper({3, InstrumentKind::grasper, 0.004, 0.012});
  const std::vector<Vec3> x{{0, 0, 0}, {0.005, 0, 0}, {0.05, 0, 0}};
  const std::vector<std::int32_t> surface{0, 1, 2};
  grasper.begin_tick(true, 11, at(0.0, 0.15));  // between the thresholds: nothing happens
  EXPECT_EQ(grasper.update_grasp(surface, x, 100), ToolEvent::none);
  grasper.begin_tick(true, 11, at(0.0, kJawGraspBelowRad - 1e-3));
  EXPECT_EQ(grasper.update_grasp(surface, x, 100), ToolEvent::grasped);
  EXPECT_EQ(grasper.held().size(), 2u);  // the two nodes within the 12 mm grasp radius
  grasper.begin_tick(true, 11, at(0.0, 0.15));  // opening a little (jitter): still held
  EXPECT_EQ(grasper.update_grasp(surface, x, 100), ToolEvent::none);
  EXPECT_EQ(grasper.held().size(), 2u);
  grasper.begin_tick(true, 11, at(0.0, kJawReleaseAboveRad + 1e-3));
  EXPECT_EQ(grasper.update_grasp(surface, x, 100), ToolEvent::let_go);
  EXPECT_TRUE(grasper.held().empty());
  // A probe never grasps; a grasper whose owner is gone lets go.
  SimulatedTool probe({1, InstrumentKind::probe});
  probe.begin_tick(true, 11, at(0.0, 0.0));
  EXPECT_EQ(probe.update_grasp(surface, x, 100), ToolEvent::none);
  grasper.begin_tick(true, 11, at(0.0, 0.0));
  grasper.update_grasp(surface, x, 100);
  grasper.begin_tick(false, 0, at(0.0, 0.0));
  EXPECT_TRUE(grasper.held().empty());
}

TEST(SimulatedTool, AContactEndsAfter50msWithoutTouchingSoABounceIsOneContact) {
  SimulatedTool tool({1, InstrumentKind::probe});
  tool.begin_tick(true, 11, at(0.0));
  EXPECT_EQ(tool.update_contact(true, 1.000), ToolEvent::contact_started);
  EXPECT_EQ(tool.update_contact(true, 1.001), ToolEvent::none);
  EXPECT_EQ(tool.update_contact(false, 1.030), ToolEvent::none);  // bounced off for 30 ms
  EXPECT_EQ(tool.update_contact(true, 1.031), ToolEvent::none);  // back: the same contact
  EXPECT_EQ(tool.update_contact(false, 1.031 + kContactEndAfterS - 1e-4), ToolEvent::none);
  EXPECT_EQ(tool.update_contact(false, 1.031 + kContactEndAfterS + 1e-4), ToolEvent::contact_ended);
  EXPECT_EQ(tool.update_contact(false, 2.0), ToolEvent::none);
  // A tool that is released while touching ends its contact at once.
  EXPECT_EQ(tool.update_contact(true, 3.0), ToolEvent::contact_started);
  tool.begin_tick(false, 0, at(0.0));
  EXPECT_EQ(tool.update_contact(true, 3.001), ToolEvent::contact_ended);
}

}  // namespace
}  // namespace viscera::runtime

namespace viscera::runtime {
namespace {

TEST(SimulatedTool, AScalpelWhoseCutButtonIsReleasedLeavesTheCutTouchingNothingUntilClear) {
  SimulatedTool scalpel({4, InstrumentKind::scalpel, 0.001});
  protocol::Command cut = at(-0.012);
  cut.buttons = kCutButton;
  scalpel.begin_tick(true, 11, cut);
  EXPECT_TRUE(scalpel.cutting());
  EXPECT_FALSE(scalpel.leaving_cut());
  scalpel.begin_tick(true, 11, at(-0.012));  // released with the blade 12 mm in the tissue
  EXPECT_FALSE(scalpel.cutting());
  EXPECT_TRUE(scalpel.leaving_cut());
  scalpel.begin_tick(true, 11, at(-0.01));  // leaving stays until the server finds it clear
  EXPECT_TRUE(scalpel.leaving_cut());
  scalpel.clear_of_tissue();
  EXPECT_FALSE(scalpel.leaving_cut());
  // Released by its owner: nothing left of it; a probe's buttons mean nothing.
  scalpel.begin_tick(true, 11, cut);
  scalpel.begin_tick(false, 0, at(-0.012));
  EXPECT_FALSE(scalpel.leaving_cut());
  SimulatedTool probe({1, InstrumentKind::probe});
  probe.begin_tick(true, 11, cut);
  probe.begin_tick(true, 11, at(-0.012));
  EXPECT_FALSE(probe.leaving_cut());
}

}  // namespace
}  // namespace viscera::runtime
