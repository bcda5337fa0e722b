// The slew limit on the force a device renders (client-sdk/force_slew_limit.hpp) against its  // SPDX-License-Identifier: Apache-2.0
// definition: no change per period larger than the rate times one period, along the change, and
// nothing changed where the force moves slower than that.
#include "viscera/client/force_slew_limit.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

using viscera::client::ForceSlewLimit;
using viscera::protocol::Vector3;

namespace {
constexpr double kPeriod = 1e-3;  // [s]
double distance(const Vector3& a, const Vector3& b) {
  return std::sqrt(std::pow(a[0] - b[0], 2) + std::pow(a[1] - b[1], 2) + std::pow(a[2] - b[2], 2));
}
}  // namespace

TEST(ForceSlewLimit, AStepBecomesARampOfTheRateAlongTheStep) {
  ForceSlewLimit slew(1000.0, kPeriod);  // 1 N/ms
  const Vector3 target{0, 9.0, 12.0};  // 15 N, not along an axis
  Vector3 before{};
  int periods = 0;
  for (double t = 0; distance(before, target) > 0; t += kPeriod, ++periods) {
    ASSERT_LT(periods, 100);
    const Vector3 now = slew.limit(target, t);
    EXPECT_LE(distance(now, before), 1.0 + 1e-12);
    // On the straight line from zero to the target: y / z stays 9 / 12.
    EXPECT_NEAR(now[1] * 12.0, now[2] * 9.0, 1e-9);
    before = now;
  }
  EXPECT_EQ(periods, 15);  // 15 N at 1 N a period
  EXPECT_EQ(slew.limited(), 14);
  EXPECT_NEAR(slew.largest_step_asked_n(), 15.0, 1e-12);
}

TEST(ForceSlewLimit, AForceSlowerThanTheLimitPassesUnchanged) {
  ForceSlewLimit slew(1000.0, kPeriod);
  // 2 N at 20 Hz: its steepest slope is 2 pi 20 x 2 N/s = 0.25 N/ms.
  for (int k = 0; k < 2000; ++k) {
    const double t = k * kPeriod;
    const Vector3 f{0, 0, 2.0 * std::sin(2 * std::numbers::pi * 20 * t)};
    const Vector3 out = slew.limit(f, t);
    ASSERT_EQ(out[2], f[2]) << "at t = " << t;
  }
  EXPECT_EQ(slew.limited(), 0);
}

TEST(ForceSlewLimit, AfterAStallTheForceStillMovesByOnePeriodsWorth) {
  ForceSlewLimit slew(1000.0, kPeriod);
  slew.limit({0, 0, 0}, 0.0);
  const Vector3 after = slew.limit({0, 0, 10.0}, 0.8);  // the loop did not run for 0.8 s
  EXPECT_NEAR(after[2], 1.0, 1e-12);
  const Vector3 back = slew.limit({0, 0, 10.0}, 0.8);  // and two calls at one time move nothing
  EXPECT_NEAR(back[2], 1.0, 1e-12);
}

TEST(ForceSlewLimit, AnInfiniteRateLimitsNothing) {
  ForceSlewLimit slew(std::numeric_limits<double>::infinity(), kPeriod);
  EXPECT_EQ(slew.limit({0, 0, 15.0}, 0.0)[2], 15.0);
  EXPECT_EQ(slew.limit({0, 0, -15.0}, 0.001)[2], -15.0);
  EXPECT_EQ(slew.limited(), 0);
}
