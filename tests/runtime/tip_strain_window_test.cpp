// The strain at an instrument spread over a window of ticks (runtime/tip_strain_window.hpp), against  // SPDX-License-Identifier: Apache-2.0
// the whole ball's average computed at once (tissue::BallStrain::at): on positions that do not
// change, the window's strain is the ball's; it holds between windows, fixes its ball where the
// window began, and says 0 out of contact.
#include "viscera/runtime/tip_strain_window.hpp"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "viscera/tissue/mesh/box_mesh.hpp"

namespace viscera::runtime {
namespace {

using tissue::Vec3;

struct Organ {
  std::shared_ptr<tissue::TetMesh> mesh = std::make_shared<tissue::TetMesh>(tissue::make_box_mesh(Vec3(0, 0, 0), Vec3(0.08, 0.08, 0.04), 16, 16, 8));
  tissue::BallStrain ball{mesh, 0.02};
  /// A dent under (cx, cy) on the top, `depth` deep.
  std::vector<Vec3> dented(double cx, double cy, double depth) const {
    std::vector<Vec3> x = mesh->nodes;
    for (Vec3& p : x) p.z() -= depth * std::exp(-(std::pow(p.x() - cx, 2) + std::pow(p.y() - cy, 2)) / 1e-4) * p.z() / 0.04;
    return x;
  }
};

TEST(TipStrainWindow, OnPositionsThatStayTheWindowGivesTheWholeBallsStrain) {
  const Organ o;
  const Vec3 at(0.04, 0.04, 0.04);
  const auto x = o.dented(0.04, 0.04, 0.006);
  const double whole = o.ball.at(x, at).strain;
  ASSERT_GT(whole, 0.01);
  TipStrainWindow w;
  EXPECT_EQ(w.after_tick(o.ball, x, std::nullopt, 20), 0.0);
  // The contact's first tick: the whole ball at once.
  EXPECT_EQ(w.after_tick(o.ball, x, at, 20), whole);
  // A window of 20 ticks on deeper positions: the value holds until the window's end, then is the
  // deeper dent's strain (summed in shares, so to rounding).
  const auto deeper = o.dented(0.04, 0.04, 0.012);
  const double deeper_whole = o.ball.at(deeper, at).strain;
  ASSERT_GT(deeper_whole, 1.5 * whole);
  for (int k = 0; k < 19; ++k) EXPECT_EQ(w.after_tick(o.ball, deeper, at, 20), whole) << "tick " << k;
  EXPECT_NEAR(w.after_tick(o.ball, deeper, at, 20), deeper_whole, 1e-14);
  // The next window's ball is fixed where it began: points that move within it change nothing.
  double v = 0;
  for (int k = 0; k < 20; ++k) v = w.after_tick(o.ball, deeper, k == 0 ? at : Vec3(0.01, 0.01, 0.04), 20);
  EXPECT_NEAR(v, deeper_whole, 1e-14);
  // Out of contact: 0; back in contact: the whole ball at once again.
  EXPECT_EQ(w.after_tick(o.ball, deeper, std::nullopt, 20), 0.0);
  EXPECT_EQ(w.after_tick(o.ball, deeper, at, 20), deeper_whole);
}

TEST(TipStrainWindow, AWindowIsTwentyMillisecondsOfTicks) {
  EXPECT_EQ(tip_strain_window_ticks(1000), 20u);
  EXPECT_EQ(tip_strain_window_ticks(500), 10u);
  EXPECT_EQ(tip_strain_window_ticks(60), 1u);
  EXPECT_EQ(tip_strain_window_ticks(10), 1u);
}

}  // namespace
}  // namespace viscera::runtime
