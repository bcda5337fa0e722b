// The local force model against its definition: linear in the displacement, push-only, clamped.
#include <gtest/gtest.h>

#include "viscera/client/local_force_model.hpp"

using namespace viscera;

namespace {
protocol::Force contact() {
  protocol::Force f;
  f.in_contact = true;
  f.force = {0, 0, 2.0};
  f.contact_normal = {0, 0, 1};
  f.stiffness = {0, 0, 0, 0, 0, 0, 0, 0, 200.0};  // 200 N/m along z
  return f;
}
}  // namespace

TEST(LocalForceModel, LinearInTheDisplacementFromTheModelPoint) {
  const auto r = client::render_local_model(contact(), {0, 0, 0.01}, {0, 0, 0.005}, 10.0);
  EXPECT_NEAR(r.force[2], 2.0 + 200.0 * 0.005, 1e-12);  // deeper: stronger
  EXPECT_FALSE(r.clamped);
  const auto shallower = client::render_local_model(contact(), {0, 0, 0.01}, {0, 0, 0.015}, 10.0);
  EXPECT_NEAR(shallower.force[2], 1.0, 1e-12);
}

TEST(LocalForceModel, PushesOnlyAndNeverBeyondTheDeviceLimit) {
  const auto out = client::render_local_model(contact(), {0, 0, 0.01}, {0, 0, 0.03}, 10.0);  // left the surface
  EXPECT_EQ(out.force[2], 0.0);
  const auto deep = client::render_local_model(contact(), {0, 0, 0.01}, {0, 0, -0.5}, 10.0);
  EXPECT_NEAR(deep.force[2], 10.0, 1e-12);
  EXPECT_TRUE(deep.clamped);
  protocol::Force free_space;
  EXPECT_EQ(client::render_local_model(free_space, {0, 0, 0}, {0, 0, -1}, 10.0).force[2], 0.0);
}
