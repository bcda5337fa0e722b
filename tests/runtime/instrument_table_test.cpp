// Instrument ownership without DDS, on a made-up clock: claims, releases, commands in order, the  // SPDX-License-Identifier: Apache-2.0
// lease that takes an instrument from a silent owner, and the hand-over between two clients.
#include "viscera/runtime/instrument_table.hpp"

#include <gtest/gtest.h>

namespace viscera::runtime {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kLease = 500 * kMs;

InstrumentTable table() { return InstrumentTable({{1, InstrumentKind::probe}, {3, InstrumentKind::grasper}}); }

protocol::Command command(std::uint32_t instrument, std::uint32_t client, std::uint64_t seq, double z = 0) {
  protocol::Command c;
  c.instrument_id = instrument;
  c.client_id = client;
  c.seq = seq;
  c.tip_position = {0, 0, z};
  return c;
}

TEST(InstrumentTable, AnInstrumentHasOneOwnerAtATime) {
  InstrumentTable t = table();
  EXPECT_EQ(t.claim(1, 11, 0), ClaimResult::claimed);
  EXPECT_EQ(t.claim(1, 12, 0), ClaimResult::taken);
  EXPECT_EQ(t.claim(1, 11, 0), ClaimResult::already_owner);
  EXPECT_EQ(t.claim(7, 11, 0), ClaimResult::unknown_instrument);
  EXPECT_EQ(t.owner(1), 11u);
  EXPECT_EQ(t.owner(3), 0u);
  EXPECT_EQ(t.owner(7), std::nullopt);
  EXPECT_EQ(t.release(1, 12), ReleaseResult::not_owner);
  EXPECT_EQ(t.release(9, 11), ReleaseResult::unknown_instrument);
  EXPECT_EQ(t.release(1, 11), ReleaseResult::released);
  EXPECT_EQ(t.claim(1, 12, 0), ClaimResult::claimed);
  const auto info = t.describe();
  ASSERT_EQ(info.size(), 2u);
  EXPECT_EQ(info[0].owner_client_id, 12u);
  EXPECT_TRUE(info[1].grasper);
}

TEST(InstrumentTable, OnlyTheOwnersNewerCommandsCount) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  EXPECT_FALSE(t.tick_commands()[0].active);  // owned, but not commanded yet: exerts nothing
  EXPECT_EQ(t.command(command(1, 11, 5, 0.1), 1), CommandResult::accepted);
  EXPECT_EQ(t.command(command(1, 11, 4, 0.2), 2), CommandResult::stale);  // out of order on the best-effort stream
  EXPECT_EQ(t.command(command(1, 12, 9, 0.3), 3), CommandResult::not_owner);
  EXPECT_EQ(t.command(command(8, 11, 9, 0.3), 3), CommandResult::unknown_instrument);
  const auto ticks = t.tick_commands();
  EXPECT_TRUE(ticks[0].active);
  EXPECT_EQ(ticks[0].owner, 11u);
  EXPECT_EQ(ticks[0].command.seq, 5u);
  EXPECT_EQ(ticks[0].command.tip_position[2], 0.1);
}

TEST(InstrumentTable, ASilentOwnerLosesItsInstrumentWhenTheLeaseRunsOut) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  t.claim(3, 12, 0);
  t.command(command(1, 11, 1), 400 * kMs);  // a command renews the lease; 12 stays silent
  EXPECT_TRUE(t.release_silent(500 * kMs, kLease).empty());  // exactly the lease: not yet
  EXPECT_EQ(t.release_silent(500 * kMs + 1, kLease), (std::vector<Ownership>{{3, 12}}));
  EXPECT_TRUE(t.release_silent(900 * kMs, kLease).empty());
  EXPECT_EQ(t.release_silent(900 * kMs + 1, kLease), (std::vector<Ownership>{{1, 11}}));
  EXPECT_EQ(t.owner(1), 0u);
  EXPECT_FALSE(t.tick_commands()[0].active);  // its command is gone with it
  // A stale command of the old owner's does not bring the instrument back.
  EXPECT_EQ(t.command(command(1, 11, 2), 901 * kMs), CommandResult::not_owner);
}

// The server stopped for 800 ms (SIGSTOP, a paused VM): its owners' commands waited unread, so the
// stall is not their silence. A client that did die meanwhile is released one lease after.
TEST(InstrumentTable, TheServersOwnStallIsNotItsOwnersSilence) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  t.command(command(1, 11, 1), 100 * kMs);  // heard last at 100 ms; the server stalls from 150 to 950 ms
  t.excuse_stall(800 * kMs);
  EXPECT_TRUE(t.release_silent(950 * kMs, kLease).empty());
  EXPECT_TRUE(t.release_silent(1400 * kMs, kLease).empty());  // 100 + 800 + 500 ms: exactly the lease
  EXPECT_EQ(t.release_silent(1400 * kMs + 1, kLease), (std::vector<Ownership>{{1, 11}}));
  t.excuse_stall(800 * kMs);  // nobody to excuse: a free instrument stays free
  EXPECT_EQ(t.owner(1), 0u);
}

TEST(InstrumentTable, HandOverMovesOwnershipWithNoMomentWithoutAnOwner) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  t.command(command(1, 11, 40, 0.05), 10 * kMs);
  EXPECT_EQ(t.hand_over(1, 12, 900, 20 * kMs), HandoverResult::not_owner);
  EXPECT_EQ(t.hand_over(5, 11, 900, 20 * kMs), HandoverResult::unknown_instrument);
  EXPECT_EQ(t.hand_over(1, 11, 900, 20 * kMs), HandoverResult::handed_over);
  EXPECT_EQ(t.owner(1), 900u);
  // The tool stays where the trainee left it until the instructor commands it...
  auto tick = t.tick_commands()[0];
  EXPECT_TRUE(tick.active);
  EXPECT_EQ(tick.owner, 900u);
  EXPECT_EQ(tick.command.tip_position[2], 0.05);
  // ...whose first command counts, whatever its sequence; the trainee's no longer do.
  EXPECT_EQ(t.command(command(1, 900, 1, 0.04), 30 * kMs), CommandResult::accepted);
  EXPECT_EQ(t.command(command(1, 11, 41, 0.06), 31 * kMs), CommandResult::not_owner);
  // The lease runs from the hand-over: the instructor is not released for the trainee's silence.
  EXPECT_TRUE(t.release_silent(530 * kMs, kLease).empty());
  // And back.
  EXPECT_EQ(t.hand_over(1, 900, 11, 40 * kMs), HandoverResult::handed_over);
  EXPECT_EQ(t.owner(1), 11u);
}

TEST(InstrumentTable, TakeOverRemembersWhomFromAndHandsBackToThem) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  t.command(command(1, 11, 7, 0.05), 10 * kMs);
  EXPECT_EQ(t.hand_back(1, 950, 15 * kMs).result, HandoverResult::not_owner);  // nothing taken yet
  const Handover h = t.take_over(1, 950, 20 * kMs);
  EXPECT_EQ(h.result, HandoverResult::handed_over);
  EXPECT_EQ(h.from, 11u);
  EXPECT_EQ(t.owner(1), 950u);
  EXPECT_EQ(t.take_over(1, 950, 21 * kMs).result, HandoverResult::already_owner);
  EXPECT_EQ(t.hand_back(1, 11, 22 * kMs).result, HandoverResult::not_owner);  // only the taker hands back
  const Handover back = t.hand_back(1, 950, 30 * kMs);
  EXPECT_EQ(back.result, HandoverResult::handed_over);
  EXPECT_EQ(back.from, 11u);
  EXPECT_EQ(t.owner(1), 11u);
  EXPECT_EQ(t.hand_back(1, 11, 31 * kMs).result, HandoverResult::not_taken_over);  // once only
  // A free instrument taken over is claimed; handed back, it is free again, and the trainee's
  // client claims it (it used to stay the instructor's until the console restarted).
  const Handover free = t.take_over(3, 950, 40 * kMs);
  EXPECT_EQ(free.result, HandoverResult::handed_over);
  EXPECT_EQ(free.from, 0u);
  EXPECT_EQ(t.claim(3, 12, 40 * kMs), ClaimResult::taken);
  const Handover freed = t.hand_back(3, 950, 41 * kMs);
  EXPECT_EQ(freed.result, HandoverResult::handed_over);
  EXPECT_EQ(freed.from, 0u);
  EXPECT_EQ(t.owner(3), 0u);
  EXPECT_EQ(t.claim(3, 12, 42 * kMs), ClaimResult::claimed);
  EXPECT_EQ(t.hand_back(3, 12, 43 * kMs).result, HandoverResult::not_taken_over);  // claimed, not taken over
  EXPECT_EQ(t.take_over(9, 950, 42 * kMs).result, HandoverResult::unknown_instrument);
}

TEST(InstrumentTable, AnInstrumentWhoseTakerGoesSilentGoesBackToItsOwner) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  t.take_over(1, 950, 100 * kMs);  // the console takes it over, then dies (or its browser's bridge does)
  t.command(command(1, 950, 1, 0.05), 200 * kMs);
  EXPECT_TRUE(t.release_silent(700 * kMs, kLease).empty());
  EXPECT_EQ(t.release_silent(700 * kMs + 1, kLease), (std::vector<Ownership>{{1, 950, 11}}));
  EXPECT_EQ(t.owner(1), 11u);  // the trainee's again, not free for anyone
  EXPECT_EQ(t.hand_back(1, 950, 701 * kMs).result, HandoverResult::not_owner);
  // Its lease starts again: silent too, it is freed.
  EXPECT_TRUE(t.release_silent(1200 * kMs + 1, kLease).empty());
  EXPECT_EQ(t.release_silent(1201 * kMs + 1, kLease), (std::vector<Ownership>{{1, 11, 0}}));
  EXPECT_EQ(t.owner(1), 0u);
  // Taken over while free, the silent taker's instrument is freed.
  t.take_over(3, 950, 2000 * kMs);
  EXPECT_EQ(t.release_silent(2500 * kMs + 1, kLease), (std::vector<Ownership>{{3, 950, 0}}));
}

TEST(InstrumentTable, ANewSceneTakesEveryInstrumentFromItsOwner) {
  InstrumentTable t = table();
  t.claim(1, 11, 0);
  t.claim(3, 12, 0);
  const auto lost = t.replace({{2, InstrumentKind::probe}});
  EXPECT_EQ(lost, (std::vector<Ownership>{{1, 11}, {3, 12}}));
  EXPECT_EQ(t.owner(1), std::nullopt);
  EXPECT_EQ(t.owner(2), 0u);
}

}  // namespace
}  // namespace viscera::runtime
