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

TEST(LocalForceRenderer, BlendsFromTheOldModelToTheNewOneWithoutAJump) {
  client::LocalForceRenderer renderer(10.0, 0.004);
  EXPECT_EQ(renderer.render({0, 0, 0}, 0.0).force[2], 0.0);  // no model yet
  renderer.update(contact(), {0, 0, 0.01}, 1.000);            // 2 N at z = 1 cm, 200 N/m
  const protocol::Vector3 x{0, 0, 0.01};
  EXPECT_NEAR(renderer.render(x, 1.0005).force[2], 2.0, 1e-12);  // the first model: no blending
  auto stiffer = contact();
  stiffer.force = {0, 0, 4.0};
  renderer.update(stiffer, {0, 0, 0.01}, 1.010);
  // At the update the force is still the old model's, then moves linearly to the new one.
  EXPECT_NEAR(renderer.render(x, 1.010).force[2], 2.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.011).force[2], 2.5, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.012).force[2], 3.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.014).force[2], 4.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.100).force[2], 4.0, 1e-12);
  EXPECT_NEAR(renderer.model_age_s(1.015), 0.005, 1e-12);
  // The device limit holds for the blend too.
  const auto deep = renderer.render({0, 0, -1.0}, 1.011);
  EXPECT_NEAR(deep.force[2], 10.0, 1e-12);
  EXPECT_TRUE(deep.clamped);
}
