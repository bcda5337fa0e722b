// The device loop's states (client-sdk/device_loop.hpp) driven by invented times, server states and  // SPDX-License-Identifier: Apache-2.0
// scene states, without a network: each way of losing the server or the instrument fades the
// force the hand feels over the fade time (LocalForceRenderer's gain, checked against the time
// the fade should take), and each way back drives again.
#include "viscera/client/device_loop.hpp"

#include <gtest/gtest.h>

using viscera::client::DeviceLoop;
using viscera::client::DeviceLoopOptions;
using viscera::client::InstrumentView;
using viscera::client::ServerState;
using Action = DeviceLoop::Action;

namespace {
constexpr double kPeriod = 1e-3;  // [s]
constexpr std::uint32_t kMe = 21, kConsole = 950, kInstrument = 1;

DeviceLoopOptions options(bool reconnect = false) {
  DeviceLoopOptions o;
  o.client_id = kMe;
  o.instrument = kInstrument;
  o.fade.fade_s = 0.25;
  o.fade.stale_after_s = 10;  // models never go stale here: only the loop's decisions fade the force
  o.reconnect = reconnect;
  return o;
}

// A model that pushes with 1 N, as if the server had just answered.
void feed_model(DeviceLoop& loop, double t) {
  viscera::protocol::Force f;
  f.force = {0, 0, 1.0};
  f.contact_normal = {0, 0, 1};
  f.in_contact = true;
  loop.renderer().update(f, {0, 0, 0}, t);
}

// Runs periods from t0 while `state` holds, until the loop's action differs from `while_action`
// or t1 passes; returns the time it stopped and the step there.
std::pair<double, DeviceLoop::Step> run(DeviceLoop& loop, double t0, double t1, ServerState state, const std::optional<InstrumentView>& scene,
                                        Action while_action) {
  for (double t = t0; t < t1; t += kPeriod) {
    const auto s = loop.next(t, state, loop.scene_check_due(t) ? scene : std::nullopt);
    if (s.action != while_action || s.end_after) return {t, s};
  }
  return {t1, {}};
}
}  // namespace

TEST(DeviceLoop, DrivesWhileTheServerIsThereAndTheInstrumentItsOwn) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  const InstrumentView mine{1, kMe, "liver"};
  const auto [t, s] = run(loop, 0, 2.0, ServerState::alive, mine, Action::drive);
  EXPECT_DOUBLE_EQ(t, 2.0) << "stopped driving: " << s.note;
  EXPECT_EQ(loop.renderer().gain(2.0), 1.0);
}

TEST(DeviceLoop, AServerGoneFadesTheForceOverTheFadeTimeThenEnds) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  const auto first = loop.next(1.0, ServerState::lost, std::nullopt);
  EXPECT_EQ(first.action, Action::drive) << "commands still go out while the force fades";
  EXPECT_NE(first.note.find("the server is gone"), std::string::npos) << first.note;
  EXPECT_NEAR(loop.renderer().gain(1.125), 0.5, 1e-9);  // half way through 0.25 s
  double t = 1.0 + kPeriod;
  for (; t < 3.0; t += kPeriod)
    if (loop.next(t, ServerState::lost, std::nullopt).action == Action::end) break;
  EXPECT_NEAR(loop.faded_t_s(), 1.25, 1.5 * kPeriod);
  EXPECT_NEAR(t, loop.faded_t_s() + kPeriod, 1e-9) << "the period that rendered zero, then the end";
  EXPECT_TRUE(loop.lost());
  EXPECT_DOUBLE_EQ(loop.server_lost_t_s(), 1.0);
}

TEST(DeviceLoop, WithReconnectItWaitsThenClaimsAgainWhenAServerIsBack) {
  DeviceLoop loop(options(true), 1);
  feed_model(loop, 0);
  loop.next(1.0, ServerState::lost, std::nullopt);
  const auto [t_wait, s_wait] = run(loop, 1.001, 5.0, ServerState::lost, std::nullopt, Action::drive);
  EXPECT_EQ(t_wait, 5.0) << "a client that reconnects never ends on its own: " << s_wait.note;
  EXPECT_FALSE(loop.lost());
  EXPECT_NEAR(loop.faded_t_s(), 1.25, 1.5 * kPeriod);
  const auto back = loop.next(5.0, ServerState::alive, std::nullopt);
  ASSERT_EQ(back.action, Action::claim_again);
  const std::string said = loop.claimed(5.0, true, "", {2, kMe, "liver"});
  EXPECT_NE(said.find("a server is back: instrument 1 claimed again"), std::string::npos) << said;
  EXPECT_EQ(loop.server_returns(), 1);
  EXPECT_EQ(loop.server_lost_t_s(), -1);
  feed_model(loop, 5.01);
  const auto [t, s] = run(loop, 5.01, 6.0, ServerState::alive, InstrumentView{2, kMe, "liver"}, Action::drive);
  EXPECT_EQ(t, 6.0) << s.note;
}

TEST(DeviceLoop, TakenOverItStandsByWithTheForceFadingAndDrivesAgainWhenHandedBack) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  run(loop, 0, 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const auto [t_taken, taken] = run(loop, 1.0, 2.0, ServerState::alive, InstrumentView{1, kConsole, "liver"}, Action::drive);
  EXPECT_LT(t_taken, 1.0 + 0.1 + kPeriod) << "noticed within a scene check (0.1 s)";
  EXPECT_EQ(taken.action, Action::render_only);
  EXPECT_NE(taken.note.find("taken over by client 950"), std::string::npos) << taken.note;
  EXPECT_EQ(loop.taken_over(), 1);
  EXPECT_NEAR(loop.renderer().gain(t_taken + 0.25), 0.0, 1e-9);
  const auto [t_stand, stand] = run(loop, t_taken + kPeriod, 3.0, ServerState::alive, InstrumentView{1, kConsole, "liver"}, Action::render_only);
  EXPECT_EQ(t_stand, 3.0) << "stands by as long as it is taken, never ends: " << stand.note;
  const auto [t_back, back] = run(loop, 3.0, 4.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::render_only);
  EXPECT_EQ(back.action, Action::drive);
  EXPECT_NE(back.note.find("handed back (owner client 21): driving it again"), std::string::npos) << back.note;
  EXPECT_LT(t_back, 3.0 + 0.1 + kPeriod);
  EXPECT_EQ(loop.instrument_lost_t_s(), -1) << "a take-over is not a loss";
}

TEST(DeviceLoop, AnInstrumentShownFreeUnderThisClientFadesOutAndEndsTheRun) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  run(loop, 0, 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const auto [t_free, free] = run(loop, 1.0, 2.0, ServerState::alive, InstrumentView{1, 0, "liver"}, Action::drive);
  EXPECT_EQ(free.action, Action::render_only);
  EXPECT_NE(free.note.find("is no longer this client's"), std::string::npos) << free.note;
  const auto [t_end, end] = run(loop, t_free + kPeriod, 3.0, ServerState::alive, InstrumentView{1, 0, "liver"}, Action::render_only);
  EXPECT_TRUE(end.end_after);
  EXPECT_NEAR(t_end - loop.instrument_lost_t_s(), 0.25, 1.5 * kPeriod) << "the force fades over the fade time, then the run ends";
  EXPECT_FALSE(loop.lost()) << "the server is still there";
}

TEST(DeviceLoop, WithReconnectAnInstrumentFreedUnderThisClientIsClaimedAgainOnceTheForceHasFaded) {
  DeviceLoop loop(options(true), 1);
  feed_model(loop, 0);
  run(loop, 0, 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const InstrumentView free{1, 0, "liver"};
  const auto [t_free, noticed] = run(loop, 1.0, 2.0, ServerState::alive, free, Action::drive);
  EXPECT_EQ(noticed.action, Action::render_only);
  EXPECT_NE(noticed.note.find("then it is claimed again (--reconnect)"), std::string::npos) << noticed.note;
  // Nothing is claimed while the force the hand feels still fades.
  const auto [t_claim, claim] = run(loop, t_free + kPeriod, 3.0, ServerState::alive, free, Action::render_only);
  ASSERT_EQ(claim.action, Action::claim_again) << claim.note;
  EXPECT_FALSE(claim.end_after);
  EXPECT_EQ(loop.renderer().gain(t_claim), 0.0);
  EXPECT_NEAR(t_claim - t_free, 0.25, 1.5 * kPeriod);
  // A refused claim is tried again a second later, not every period.
  const std::string refused = loop.claimed(t_claim, false, "no answer within 5 s", free);
  EXPECT_NE(refused.find("not claimed again: no answer within 5 s; trying again in 1 s"), std::string::npos) << refused;
  const auto [t_retry, retry] = run(loop, t_claim + kPeriod, t_claim + 3.0, ServerState::alive, free, Action::render_only);
  ASSERT_EQ(retry.action, Action::claim_again);
  EXPECT_NEAR(t_retry - t_claim, 1.0, 1.5 * kPeriod);
  const std::string held = loop.claimed(t_retry, true, "", {1, kMe, "liver"});
  EXPECT_NE(held.find("instrument 1 claimed again"), std::string::npos) << held;
  EXPECT_EQ(loop.instrument_lost_t_s(), -1);
  EXPECT_EQ(loop.instrument_losses(), 1);
  feed_model(loop, t_retry + 0.01);
  const auto [t, s] = run(loop, t_retry + 0.01, t_retry + 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  EXPECT_NEAR(t, t_retry + 1.0, 1e-9) << "drives again: " << s.note;
  EXPECT_EQ(loop.renderer().gain(t), 1.0) << "the force faded back in";
}

TEST(DeviceLoop, WithReconnectAFreedInstrumentAnotherClientTookIsNotClaimedWhileItHoldsIt) {
  DeviceLoop loop(options(true), 1);
  feed_model(loop, 0);
  run(loop, 0, 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const auto [t_free, noticed] = run(loop, 1.0, 2.0, ServerState::alive, InstrumentView{1, 0, "liver"}, Action::drive);
  ASSERT_EQ(noticed.action, Action::render_only);
  // Another client claims it before the fade ends: this one stands by and never claims.
  const auto [t_other, other] = run(loop, t_free + kPeriod, t_free + 5.0, ServerState::alive, InstrumentView{1, 22, "liver"}, Action::render_only);
  EXPECT_NEAR(t_other, t_free + 5.0, 1e-9) << "claimed while another held it: " << other.note;
  EXPECT_TRUE(loop.standing_by());
  // Free again: claimed.
  const auto [t_again, again] = run(loop, t_free + 5.0, t_free + 7.0, ServerState::alive, InstrumentView{1, 0, "liver"}, Action::render_only);
  EXPECT_EQ(again.action, Action::claim_again) << again.note;
  EXPECT_LT(t_again, t_free + 5.0 + 0.1 + 2 * kPeriod);
}

TEST(DeviceLoop, ANewSceneLoadedWhileTheFreedInstrumentFadesIsClaimedAndDrivenAgain) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  run(loop, 0, 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const auto [t_free, noticed] = run(loop, 1.0, 2.0, ServerState::alive, InstrumentView{1, 0, "liver"}, Action::drive);
  ASSERT_EQ(noticed.action, Action::render_only);
  const auto [t_scene, scene] = run(loop, t_free + kPeriod, 2.0, ServerState::alive, InstrumentView{2, 0, "liver-12k"}, Action::render_only);
  ASSERT_EQ(scene.action, Action::claim_again) << scene.note;
  loop.claimed(t_scene, true, "", {2, kMe, "liver-12k"});
  EXPECT_EQ(loop.instrument_lost_t_s(), -1) << "claimed: no longer lost, so the run does not end with status 5";
  feed_model(loop, t_scene + 0.01);
  const auto [t, s] = run(loop, t_scene + 0.01, t_scene + 1.0, ServerState::alive, InstrumentView{2, kMe, "liver-12k"}, Action::drive);
  EXPECT_NEAR(t, t_scene + 1.0, 1e-9) << s.note;
}

TEST(DeviceLoop, AGapBetweenPeriodsLongerThanTheLeaseIsNamedAsThisProcesssOwnStall) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  run(loop, 0, 1.0, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const auto short_gap = loop.next(1.4, ServerState::alive, std::nullopt);  // 0.4 s: within the lease
  EXPECT_EQ(short_gap.note, "");
  EXPECT_EQ(loop.stall_s(), 0);
  const auto stalled = loop.next(2.2, ServerState::alive, std::nullopt);
  EXPECT_NE(stalled.note.find("this process did not run for 0.80 s, longer than the server's 0.5 s lease"), std::string::npos) << stalled.note;
  EXPECT_NEAR(loop.stall_s(), 0.8, 1e-9);
  EXPECT_DOUBLE_EQ(loop.stall_end_t_s(), 2.2);
  const auto lost = loop.next(2.201, ServerState::lost, std::nullopt);
  EXPECT_NE(lost.note.find("just after this process's own stall"), std::string::npos) << lost.note;
  // A claim that blocks for seconds is not a stall.
  DeviceLoop again(options(true), 1);
  again.next(0, ServerState::lost, std::nullopt);
  run(again, 0.001, 1.0, ServerState::lost, std::nullopt, Action::drive);
  ASSERT_EQ(again.next(1.0, ServerState::alive, std::nullopt).action, Action::claim_again);
  again.claimed(1.0, true, "", {1, kMe, "liver"});
  EXPECT_EQ(again.next(4.0, ServerState::alive, std::nullopt).note, "");
  EXPECT_EQ(again.stall_s(), 0);
}

TEST(DeviceLoop, ANewSceneMeansClaimingAgainAndTheNewGenerationThen) {
  DeviceLoop loop(options(), 1);
  feed_model(loop, 0);
  run(loop, 0, 0.5, ServerState::alive, InstrumentView{1, kMe, "liver"}, Action::drive);
  const auto [t, s] = run(loop, 0.5, 1.0, ServerState::alive, InstrumentView{2, 0, "liver-nodule"}, Action::drive);
  ASSERT_EQ(s.action, Action::claim_again);
  const std::string said = loop.claimed(t, false, "instrument 1 is held by client 22", {2, 22, "liver-nodule"});
  EXPECT_NE(said.find("the server loaded scene liver-nodule: instrument 1 could not be claimed again: instrument 1 is held by client 22"),
            std::string::npos)
      << said;
  // Next check, same generation: the instrument is another's, so the device stands by.
  const auto [t2, s2] = run(loop, t + kPeriod, 2.0, ServerState::alive, InstrumentView{2, 22, "liver-nodule"}, Action::drive);
  EXPECT_EQ(s2.action, Action::render_only);
  EXPECT_LT(t2, t + 0.1 + 2 * kPeriod);
}

TEST(DeviceLoop, AJumpOfTheOrganRampsTheForceAndSaysSo) {
  DeviceLoop loop(options(), 1);
  const viscera::protocol::Vector3 x{0, 0, 0};
  feed_model(loop, 0);  // 1 N
  EXPECT_EQ(loop.organ_epoch(0.0, 3), "");  // the first epoch seen is no jump
  EXPECT_EQ(loop.organ_epoch(0.5, 3), "");
  EXPECT_NEAR(loop.renderer().render(x, 0.99).force[2], 1.0, 1e-12);
  viscera::protocol::Force after;  // reset under the tool: it is out of contact at once
  loop.renderer().update(after, x, 1.0);
  const std::string said = loop.organ_epoch(1.0, 4);
  EXPECT_NE(said.find("the force ramps to the new one over 0.10 s"), std::string::npos) << said;
  EXPECT_NEAR(loop.renderer().render(x, 1.0).force[2], 1.0, 1e-12);  // from what the hand felt ...
  EXPECT_NEAR(loop.renderer().render(x, 1.05).force[2], 0.5, 1e-12);  // ... linearly ...
  EXPECT_NEAR(loop.renderer().render(x, 1.1).force[2], 0.0, 1e-12);  // ... to the new force, in 0.1 s
}

TEST(DeviceLoop, AfterAClaimTheForceRampsFromTheFirstAnswer) {
  DeviceLoop loop(options(), 1);
  const viscera::protocol::Vector3 x{0, 0, 0};
  feed_model(loop, 0);
  const auto [t, s] = run(loop, 0.0, 1.0, ServerState::alive, InstrumentView{2, 0, "liver-12k"}, Action::drive);
  ASSERT_EQ(s.action, Action::claim_again);
  viscera::protocol::Force none;  // nothing felt while the new scene was loaded
  loop.renderer().update(none, x, t);
  EXPECT_EQ(loop.renderer().render(x, t + 0.01).force[2], 0.0);  // after the 3 ms blend
  loop.claimed(t + 0.5, true, "", {2, kMe, "liver-12k"});
  EXPECT_EQ(loop.organ_epoch(t + 0.6, 9), "");  // the new organ's epoch, with the first answer: no second jump
  feed_model(loop, t + 0.6);  // the first answer, 0.1 s after the claim: 1 N, the tool deep in the tissue
  EXPECT_EQ(loop.renderer().render(x, t + 0.6).force[2], 0.0);
  EXPECT_NEAR(loop.renderer().render(x, t + 0.65).force[2], 0.5, 1e-9);
  EXPECT_NEAR(loop.renderer().render(x, t + 0.7).force[2], 1.0, 1e-9);
  feed_model(loop, t + 0.8);  // and only after that answer
  EXPECT_NEAR(loop.renderer().render(x, t + 0.8).force[2], 1.0, 1e-12);
}
