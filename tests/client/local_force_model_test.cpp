// The local force model against its definition: linear in the displacement, push-only, clamped.  // SPDX-License-Identifier: Apache-2.0
#include "viscera/client/local_force_model.hpp"

#include <algorithm>

#include <gtest/gtest.h>

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

TEST(LocalForceModel, AModelWithFrictionHoldsSidewaysUpToTheConeAndSlidesOnIt) {
  // A stuck contact's model: 2 N along +z, 200 N/m in every direction, mu 0.3. Moved sideways by
  // dx, the tangential force is 200 dx (linear) until it reaches 0.3 x 2 N at 3 mm; beyond, it
  // stays on the cone, in the direction it pulls, while the normal force is unchanged.
  protocol::Force f = contact();
  f.stiffness = {200.0, 0, 0, 0, 200.0, 0, 0, 0, 200.0};
  f.friction_mu = 0.3;
  for (const double dx : {0.001, 0.0029, 0.004, 0.02}) {
    const auto r = client::render_local_model(f, {0, 0, 0.01}, {dx, 0, 0.01}, 10.0);
    EXPECT_NEAR(r.force[2], 2.0, 1e-12) << dx;
    EXPECT_NEAR(r.force[0], -std::min(200.0 * dx, 0.3 * 2.0), 1e-12) << dx;
    EXPECT_EQ(r.force[1], 0.0);
  }
  // Without friction (0: the penalty contact, an older server) the model is rendered as it is.
  f.friction_mu = 0.0;
  EXPECT_NEAR(client::render_local_model(f, {0, 0, 0.01}, {0.02, 0, 0.01}, 10.0).force[0], -4.0, 1e-12);
}

TEST(LocalForceRenderer, BlendsFromTheOldModelToTheNewOneWithoutAJump) {
  client::LocalForceRenderer renderer(10.0, 0.004);
  EXPECT_EQ(renderer.render({0, 0, 0}, 0.0).force[2], 0.0);  // no model yet
  renderer.update(contact(), {0, 0, 0.01}, 1.000);  // 2 N at z = 1 cm, 200 N/m
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

// When the server stops answering, the force fades linearly from full to none over fade_s,
// starting stale_after_s after the newest model: F(t) = F0 (1 - (t - t_stale) / fade_s).
TEST(LocalForceRenderer, FadesLinearlyToZeroWhenTheModelsStop) {
  client::LocalForceRenderer renderer(10.0, 0.0, {0.2, 0.4});
  const protocol::Vector3 x{0, 0, 0.01};
  renderer.update(contact(), x, 5.0);  // 2 N
  EXPECT_NEAR(renderer.render(x, 5.2).force[2], 2.0, 1e-12);  // stale from 5.2 s
  EXPECT_NEAR(renderer.render(x, 5.3).force[2], 2.0 * 0.75, 1e-12);
  EXPECT_NEAR(renderer.render(x, 5.5).force[2], 2.0 * 0.25, 1e-12);
  EXPECT_NEAR(renderer.render(x, 5.6).force[2], 0.0, 1e-12);
  EXPECT_EQ(renderer.render(x, 5.601).force[2], 0.0);
  EXPECT_EQ(renderer.render(x, 9.0).force[2], 0.0);
  // Never a step: over the fade, no two samples 1 ms apart differ by more than F0 x 1 ms / fade_s.
  double before = renderer.render(x, 5.0).force[2];
  for (double t = 5.001; t < 5.7; t += 0.001) {
    const double now = renderer.render(x, t).force[2];
    EXPECT_LE(std::abs(now - before), 2.0 * 0.001 / 0.4 + 1e-9) << "at t = " << t;
    before = now;
  }
}

TEST(LocalForceRenderer, AServerKnownToBeGoneFadesAtOnceAndAReturningOneFadesBackIn) {
  client::LocalForceRenderer renderer(10.0, 0.0, {0.25, 0.2});
  const protocol::Vector3 x{0, 0, 0.01};
  renderer.update(contact(), x, 1.0);
  renderer.server_lost(1.05);  // before the model goes stale
  EXPECT_NEAR(renderer.render(x, 1.05).force[2], 2.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.1).force[2], 1.5, 1e-12);
  EXPECT_NEAR(renderer.gain(1.15), 0.5, 1e-12);
  // A model again (a server came back) at 1.15 s: from the gain then, back up at the same rate.
  renderer.update(contact(), x, 1.15);
  EXPECT_NEAR(renderer.gain(1.15), 0.5, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.2).force[2], 2.0 * 0.75, 1e-12);
  EXPECT_NEAR(renderer.gain(1.25), 1.0, 1e-12);
  EXPECT_NEAR(renderer.gain(1.3), 1.0, 1e-12);
}

TEST(LocalForceRenderer, AfterARestartTheForceRampsFromWhatTheHandFeltToTheNewModel) {
  client::LocalForceRenderer renderer(10.0, 0.0, {.stale_after_s = 10.0, .fade_s = 0.05, .fade_in_s = 0.2});
  const protocol::Vector3 x{0, 0, 0.01};
  renderer.update(contact(), x, 1.0);
  EXPECT_NEAR(renderer.render(x, 1.09).force[2], 2.0, 1e-12);
  auto stiffer = contact();  // the organ jumped under the tool: 4 N at once
  stiffer.force = {0, 0, 4.0};
  renderer.update(stiffer, x, 1.1);
  renderer.restart(1.1);
  EXPECT_NEAR(renderer.render(x, 1.1).force[2], 2.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.15).force[2], 2.5, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.2).force[2], 3.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 1.3).force[2], 4.0, 1e-12);
  // Down as well: the tool withdrawn from the tissue (no contact) after another jump.
  renderer.update(protocol::Force{}, x, 2.0);
  renderer.restart(2.0);
  EXPECT_NEAR(renderer.render(x, 2.0).force[2], 4.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 2.1).force[2], 2.0, 1e-12);
  EXPECT_NEAR(renderer.render(x, 2.2).force[2], 0.0, 1e-12);
}

TEST(LocalForceRenderer, AContactRegainedWithForceRampsInAndATouchDoesNot) {
  client::LocalForceRenderer renderer(10.0, 0.0, {.stale_after_s = 10.0, .fade_s = 0.05, .fade_in_s = 0.2, .contact_onset_n = 1.0});
  const protocol::Vector3 x{0, 0, 0.01};
  protocol::Force off;  // out of contact
  renderer.update(off, x, 1.0);
  auto touch = contact();
  touch.force = {0, 0, 0.4};  // a first touch: below the 1 N onset
  renderer.update(touch, x, 1.001);
  EXPECT_NEAR(renderer.render(x, 1.001).force[2], 0.4, 1e-12);
  renderer.update(off, x, 1.002);  // lost (a flicker) ...
  EXPECT_EQ(renderer.render(x, 1.002).force[2], 0.0);
  renderer.update(contact(), x, 1.003);  // ... and back at 2 N: a jump, ramped in
  EXPECT_EQ(renderer.render(x, 1.003).force[2], 0.0);
  EXPECT_NEAR(renderer.render(x, 1.103).force[2], 1.0, 1e-12);
  renderer.update(contact(), x, 1.5);  // staying in contact does not ramp again
  EXPECT_NEAR(renderer.render(x, 1.5).force[2], 2.0, 1e-12);
}
