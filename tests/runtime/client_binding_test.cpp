// A client id belongs to the DDS participant that uses it while that participant keeps talking  // SPDX-License-Identifier: Apache-2.0
// (and, under DDS Security, to its certificate): on a made-up clock (ClientBinding), and through
// the whole server in one process, where a second participant reusing a client's id can neither
// steer nor release that client's instrument until the holder has been silent for the lease.
#include "viscera/runtime/client_binding.hpp"

#include <algorithm>
#include <thread>

#include <gtest/gtest.h>

#include "memory_endpoints.hpp"

namespace viscera::runtime {
namespace {

namespace proto = viscera::protocol;
using testing::LiveServer;
using testing::MemoryEndpoints;

constexpr std::int64_t kLease = 500'000'000;  // ns

TEST(ClientBinding, AnIdBelongsToItsFirstParticipantWhileItTalks) {
  ClientBinding b(kLease, false);
  EXPECT_TRUE(b.admit(7, {100, 1}, 0));
  EXPECT_TRUE(b.admit(7, {100, 1}, 400'000'000));
  EXPECT_FALSE(b.admit(7, {200, 1}, 800'000'000)) << "the holder spoke 0.4 s ago, within the lease";
  EXPECT_FALSE(b.admit(7, {200, 1}, 900'000'000)) << "a refusal does not count as the holder's silence";
  EXPECT_TRUE(b.admit(8, {200, 1}, 900'000'000)) << "another id is free";
  EXPECT_TRUE(b.admit(7, {100, 1}, 900'000'000));
}

TEST(ClientBinding, ASilentHoldersIdPassesOnAndTheOldHolderIsThenRefused) {
  ClientBinding b(kLease, false);
  EXPECT_TRUE(b.admit(7, {100, 1}, 0));
  EXPECT_FALSE(b.admit(7, {200, 1}, kLease));  // silent exactly the lease: still held
  EXPECT_TRUE(b.admit(7, {200, 1}, kLease + 1));
  EXPECT_FALSE(b.admit(7, {100, 1}, kLease + 2)) << "the id now belongs to participant 200";
}

TEST(ClientBinding, ASprayOfIdsDoesNotGrowTheTableWithoutBound) {
  ClientBinding b(kLease, false);
  for (std::uint32_t id = 1; id <= 5000; ++id) ASSERT_TRUE(b.admit(id, {100, 1}, 0));
  EXPECT_EQ(b.held(), 5000u);  // all within the lease: each is still held
  for (std::uint32_t id = 5001; id <= 10000; ++id) ASSERT_TRUE(b.admit(id, {100, 1}, 2 * kLease));
  EXPECT_LE(b.held(), 5000u) << "the silent ones were forgotten";
}

// Under DDS Security: an id stays with the certificate (identity) that first used it, while a
// restarted client of that certificate (a new participant) takes it back after the lease.
TEST(ClientBinding, BoundByIdentityAnIdStaysWithItsCertificate) {
  constexpr std::uint64_t kHaptic = 0xb6ea9485ce15, kConsole = 0x95a861549b7a;  // two certificates' identities
  ClientBinding b(kLease, true);
  EXPECT_TRUE(b.admit(7, {100, kHaptic}, 0));
  EXPECT_FALSE(b.admit(7, {200, kConsole}, 10 * kLease)) << "another certificate, however long the holder has been silent";
  EXPECT_FALSE(b.admit(7, {300, kHaptic}, kLease)) << "the same certificate, another process: within the lease, refused";
  EXPECT_TRUE(b.admit(7, {300, kHaptic}, kLease + 1)) << "the holder's certificate, restarted, after the lease";
  EXPECT_FALSE(b.admit(7, {100, kHaptic}, kLease + 2)) << "the id now belongs to the new participant";
  EXPECT_FALSE(b.admit(7, {200, kConsole}, 100 * kLease));
  EXPECT_TRUE(b.admit(8, {200, kConsole}, 100 * kLease)) << "another id is free";
  // The same history bound by participant: the silent holder's id passes to any participant.
  ClientBinding p(kLease, false);
  EXPECT_TRUE(p.admit(7, {100, kHaptic}, 0));
  EXPECT_TRUE(p.admit(7, {200, kConsole}, 10 * kLease));
}

// The whole server in one process: client 7 (participant 1) claims instrument 1 and presses; an
// impostor (participant 2) sends commands and a release under id 7. Only participant 1 is heard
// until it goes silent; then the instrument and the id come free and the impostor may claim them.
TEST(ClientBinding, AnotherParticipantCannotSteerOrReleaseAClientsInstrumentUnderItsId) {
  LiveServer live(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  MemoryEndpoints& endpoints = live.endpoints;
  const auto owner = [&] {
    const auto scenes = endpoints.decoded<proto::Scene>(endpoints.scenes, proto::decode_scene);
    return scenes.empty() ? 0u : scenes.back().instruments.at(0).owner_client_id;
  };
  const auto wait_for_owner = [&](std::uint32_t want) {
    for (int k = 0; k < 200 && owner() != want; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return owner();
  };
  endpoints.push_request({7, proto::Action::claim_instrument, 1}, 1);
  ASSERT_EQ(wait_for_owner(7), 7u);

  const auto command = [&](std::uint64_t seq, double z) {
    proto::Command c;
    c.instrument_id = 1;
    c.client_id = 7;
    c.seq = seq;
    c.client_stamp_ns = proto::now_ns();
    c.tip_position = {0, 0, z};
    return c;
  };
  for (int k = 1; k <= 300; ++k) {
    if (k % 50 == 0) endpoints.push_command(command(static_cast<std::uint64_t>(k), 1.0), 1);  // the owner, now and then
    endpoints.push_command(command(1'000'000 + static_cast<std::uint64_t>(k), 0.0), 2);  // the impostor, newer sequence
    if (k == 150) endpoints.push_request({7, proto::Action::release_instrument, 1}, 2);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(owner(), 7u) << "the impostor's release under id 7 was refused";
  const auto forces = endpoints.decoded<proto::Force>(endpoints.forces, proto::decode_force);
  const bool impostor_answered = std::any_of(forces.begin(), forces.end(), [](const proto::Force& f) { return f.command_seq >= 1'000'000; });
  EXPECT_FALSE(impostor_answered) << "no command of the impostor was answered";
  EXPECT_TRUE(std::any_of(forces.begin(), forces.end(), [](const proto::Force& f) { return f.command_seq > 0 && f.command_seq < 1'000'000; }))
      << "the owner's commands were";

  // The owner goes silent: after the lease its instrument and its id are free.
  ASSERT_EQ(wait_for_owner(0), 0u);
  endpoints.push_request({7, proto::Action::claim_instrument, 1}, 2);
  EXPECT_EQ(wait_for_owner(7), 7u) << "the id passed to participant 2 once its holder was silent";
  EXPECT_GE(live.stop().rejected_other_participant, 301u);  // 300 commands and the release
}

}  // namespace
}  // namespace viscera::runtime
