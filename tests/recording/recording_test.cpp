// Session recordings without a network: the writer's file read back by the reader and checked  // SPDX-License-Identifier: Apache-2.0
// against the FlatBuffers reflection of the schemas it carries (an independent decoder), drops
// counted from sequence numbers, the replay clock on made-up time, the lockstep plan and the
// re-simulation check on a synthetic session whose inputs and ticks are known by construction.
#include "viscera/recording/recording.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <flatbuffers/reflection.h>
#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/mcap/mcap_writer.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/recording/lockstep_plan.hpp"
#include "viscera/recording/playback_clock.hpp"
#include "viscera/recording/recording_format.hpp"
#include "viscera/recording/recording_writer.hpp"
#include "viscera/recording/resimulation_check.hpp"
#include "viscera/recording/sequence_gaps.hpp"

namespace fs = std::filesystem;
namespace proto = viscera::protocol;
namespace mcap = viscera::mcap;
using namespace viscera::recording;
using viscera::common::InputError;

namespace {

fs::path temp_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("viscera_recording_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <typename Message>
std::string what_throws(const Message& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// A synthetic session as the server would have stamped it: scene loaded at tick 100 (its files
/// attached), instrument 1 claimed by client 7 at tick 100, its commands 1..4 stepped over ticks
/// 101..110 (a new one at 101, 104, 108), one answered at once on the state after tick 105, a
/// material change (request 3) that took effect at tick 106, frames after ticks 103 and 110.
struct SyntheticSession {
  static constexpr std::uint32_t kClient = 7, kInstrument = 1;
  std::vector<proto::Command> commands;
  std::vector<proto::Force> forces;
  std::vector<proto::Event> events;
  std::vector<proto::MeshFrame> frames;
  proto::SessionRequest material_request;
  proto::SceneFiles scene_files;

  SyntheticSession() {
    for (std::uint64_t seq = 1; seq <= 4; ++seq) {
      proto::Command c;
      c.instrument_id = kInstrument;
      c.client_id = kClient;
      c.seq = seq;
      c.tip_position = {0.01 * static_cast<double>(seq), 0.02, -0.001 * static_cast<double>(seq)};
      c.client_stamp_ns = 5'000'000 + static_cast<std::int64_t>(seq);
      commands.push_back(c);
    }
    const auto command_at = [](std::uint64_t tick) -> std::uint64_t { return tick < 104 ? 1 : tick < 108 ? 2 : 3; };
    for (std::uint64_t tick = 101; tick <= 110; ++tick) {
      proto::Force f;
      f.instrument_id = kInstrument;
      f.client_id = kClient;
      f.command_seq = command_at(tick);
      f.command_client_stamp_ns = commands[f.command_seq - 1].client_stamp_ns;
      f.step_time_ns = 1000;
      f.tick = tick;
      f.in_contact = tick >= 103;
      f.force = {0.0, 0.0, 0.1 * static_cast<double>(tick - 100) / 3.0};  // not exact in binary
      f.penetration_m = 1e-4 * static_cast<double>(tick - 100);
      f.stiffness[8] = 250.0;
      forces.push_back(f);
    }
    proto::Force answered = forces[4];  // command 4, answered on the state after tick 105
    answered.command_seq = 4;
    answered.command_client_stamp_ns = commands[3].client_stamp_ns;
    answered.step_time_ns = 0;
    answered.tick = 105;
    forces.push_back(answered);

    proto::Event claim;
    claim.kind = proto::EventKind::instrument_claimed;
    claim.instrument_id = kInstrument;
    claim.client_id = kClient;
    claim.tick = 100;
    claim.sim_time_s = 0.1;
    events.push_back(claim);
    material_request.client_id = kClient;
    material_request.action = proto::Action::set_material;
    material_request.request_seq = 3;
    material_request.material.youngs_modulus_pa = 6000.0;
    proto::Event material;
    material.kind = proto::EventKind::material_changed;
    material.client_id = kClient;
    material.request_seq = 3;
    material.tick = 106;
    material.sim_time_s = 0.106;
    events.push_back(material);

    for (std::uint64_t tick : {103, 110}) {
      proto::MeshFrame m;
      m.mesh_id = 1;
      m.frame = tick;
      m.tick = tick;
      m.sim_time_s = 1e-3 * static_cast<double>(tick);
      m.positions = {0.0F, 0.0F, 0.0F, 0.01F, 0.0F, -1e-4F * static_cast<float>(tick - 100), 0.0F, 0.01F, 0.0F};
      frames.push_back(m);
    }

    scene_files.generation = 1;
    scene_files.server_version = "viscera test";
    scene_files.settings_json = R"({"physics_rate_hz": 1000})";
    scene_files.first_tick = 100;
    scene_files.sim_time_s = 0.1;
    const auto file = [](const std::string& role, const std::string& path, const std::string& content) {
      proto::LoadedFile f;
      f.role = role;
      f.path = path;
      f.content = bytes_of(content);
      f.sha256 = proto::sha256_hex(f.content);
      return f;
    };
    scene_files.files = {file("scene", "scenes/probe.json", R"({"name": "probe"})"), file("mesh", "meshes/cube.msh", "$MeshFormat\n4.1 0 8\n"),
                         file("material", "materials/liver.json", R"({"youngs_modulus_pa": 4000})")};
  }

  /// Records it; forces of the instrument's writer lose the samples numbered `lost`.
  void record(const fs::path& path, const std::vector<std::uint64_t>& lost = {}, const std::string& compression = "zstd") const {
    mcap::WriterOptions options;
    options.compression = compression;
    options.chunk_bytes = 512;  // several chunks, for the reader to walk
    RecordingWriter w(path.string(), {0, "test", {}, "recording_test"}, options);
    std::uint64_t t = 1'000'000'000;
    const auto add = [&](proto::Stream s, std::uint32_t key, std::uint64_t writer, std::uint64_t seq, const std::vector<std::uint8_t>& payload) {
      w.add({s, key, seq, static_cast<std::int64_t>(t - 500), writer, payload}, t);
      t += 1'000'000;
    };
    add(proto::Stream::scene_files, 0, 10, 1, proto::encode(scene_files));
    add(proto::Stream::event, 0, 11, 1, proto::encode(events[0]));
    add(proto::Stream::session_request, kClient, 12, 1, proto::encode(material_request));
    std::uint64_t seq = 0;
    for (const auto& c : commands) add(proto::Stream::instrument_command, kInstrument, 13, c.seq, proto::encode(c));
    for (const auto& f : forces) {
      ++seq;
      if (std::find(lost.begin(), lost.end(), seq) == lost.end()) add(proto::Stream::force_feedback, kInstrument, 14, seq, proto::encode(f));
    }
    add(proto::Stream::event, 0, 11, 2, proto::encode(events[1]));
    for (std::size_t i = 0; i < frames.size(); ++i) add(proto::Stream::mesh_frame, 1, 15, i + 1, proto::encode(frames[i]));
    // A later run of the same client, with the same id: its commands and its request 3 have
    // the same numbers as this run's, and must not be taken for them.
    for (auto c : commands) {
      c.client_stamp_ns += 1'000'000;
      c.tip_position[0] = -c.tip_position[0];
      add(proto::Stream::instrument_command, kInstrument, 16, c.seq, proto::encode(c));
    }
    auto later_request = material_request;
    later_request.material.youngs_modulus_pa = 9000.0;
    add(proto::Stream::session_request, kClient, 17, 1, proto::encode(later_request));
    w.close();
  }

  /// What a lockstep server that reproduces the session returns for `tick`.
  proto::LockstepResult result(std::uint64_t tick) const {
    proto::LockstepResult r;
    r.tick = tick;
    for (const auto& f : forces)
      if ((f.step_time_ns > 0 ? f.tick : f.tick + 1) == tick) r.forces.push_back(proto::encode(f));
    for (const auto& e : events)
      if (e.tick == tick) r.events.push_back(proto::encode(e));
    for (const auto& m : frames)
      if (m.tick == tick) r.frame = proto::encode(m);
    return r;
  }
};

}  // namespace

TEST(PlaybackClock, RunsAtItsRateStandsStillWhilePausedAndSeeks) {
  using namespace std::chrono;
  const PlaybackClock::WallTime t0{seconds(1000)};
  PlaybackClock clock(5'000'000'000, 2.0, t0);
  EXPECT_EQ(clock.position(t0 + milliseconds(1500)), 8'000'000'000u);  // 5 s + 2 x 1.5 s
  // due() is position()'s inverse: recording time 9 s comes 2 s of wall time after the start.
  EXPECT_EQ(duration_cast<milliseconds>(clock.due(9'000'000'000) - t0).count(), 2000);
  clock.pause(t0 + seconds(2));
  EXPECT_TRUE(clock.paused());
  EXPECT_EQ(clock.position(t0 + seconds(60)), 9'000'000'000u);
  EXPECT_EQ(clock.due(10'000'000'000), PlaybackClock::WallTime::max());
  clock.seek(1'000'000'000, t0 + seconds(61));  // paused stays paused
  EXPECT_TRUE(clock.paused());
  EXPECT_EQ(clock.position(t0 + seconds(70)), 1'000'000'000u);
  clock.resume(t0 + seconds(70));
  EXPECT_EQ(clock.position(t0 + seconds(71)), 3'000'000'000u);
  // Seeking backwards while running: time runs on from the new place.
  clock.seek(500'000'000, t0 + seconds(72));
  EXPECT_EQ(clock.position(t0 + milliseconds(72250)), 1'000'000'000u);
}

TEST(SequenceGaps, CountsEachWritersMissingNumbersAndRunsApart) {
  SequenceGaps g;
  for (std::uint64_t s : {1, 2, 5, 6, 9, 10}) g.add(100, s);  // 3,4 and 7,8 lost: 4 numbers, 2 runs
  for (std::uint64_t s : {20, 21, 22}) g.add(200, s);  // joined late at 20: nothing lost
  g.add(200, 21);  // a repeat
  EXPECT_EQ(g.missing(), 4u);
  const auto& a = g.writers().at(100);
  EXPECT_EQ(a.missing, 4u);
  EXPECT_EQ(a.gaps, 2u);
  EXPECT_EQ(a.received, 6u);
  const auto& b = g.writers().at(200);
  EXPECT_EQ(b.first, 20u);
  EXPECT_EQ(b.missing, 0u);
  EXPECT_EQ(b.out_of_order, 1u);
  // Two keys of one writer handed over interleaved: 4 before 3 is late, not lost; a late number in
  // the middle of a run splits it, at its end shortens it.
  SequenceGaps late;
  for (std::uint64_t s : {1, 2, 4, 3, 5, 10, 7, 11}) late.add(1, s);  // 6, 8, 9 lost: runs {6} {8, 9}
  EXPECT_EQ(late.writers().at(1).missing, 3u);
  EXPECT_EQ(late.writers().at(1).gaps, 2u);
  EXPECT_EQ(late.writers().at(1).out_of_order, 2u);
  late.add(1, 9);
  EXPECT_EQ(late.writers().at(1).missing, 2u);
  EXPECT_EQ(late.writers().at(1).gaps, 2u);
  late.add(1, 6);
  EXPECT_EQ(late.writers().at(1).missing, 1u);
  EXPECT_EQ(late.writers().at(1).gaps, 1u);
  late.add(1, 6);  // a repeat changes nothing but the count
  EXPECT_EQ(late.writers().at(1).missing, 1u);
  EXPECT_EQ(late.writers().at(1).out_of_order, 5u);
}

TEST(Recording, WhatIsWrittenReadsBackAndDecodesByTheSchemasItCarries) {
  const auto dir = temp_dir("round_trip");
  const SyntheticSession session;
  for (const std::string compression : {"zstd", "lz4", ""}) {
    SCOPED_TRACE(compression.empty() ? "uncompressed" : compression);
    const auto path = dir / ("session_" + compression + ".mcap");
    session.record(path, {}, compression);
    Recording r(path.string());
    EXPECT_EQ(r.info().at("schema_version"), std::to_string(proto::kSchemaVersion));
    ASSERT_TRUE(r.summary().statistics);
    const std::uint64_t expected = 2 * 4 + session.forces.size() + 2 + 2 + session.frames.size();  // all but the scene files
    EXPECT_EQ(r.summary().statistics->message_count, expected);
    EXPECT_GT(r.summary().chunks.size(), 2u);

    // Every payload verifies against the recorded schema by FlatBuffers' own reflection, and
    // decodes to what was sent.
    std::map<proto::Stream, int> seen;
    std::uint64_t last_log = 0;
    std::size_t force_index = 0;
    r.for_each([&](const RecordedChannel& ch, const mcap::Message& m) {
      EXPECT_GE(m.log_time, last_log);
      last_log = m.log_time;
      ++seen[ch.stream];
      const auto& channel = *std::find_if(r.summary().channels.begin(), r.summary().channels.end(), [&](const auto& c) { return c.id == ch.id; });
      const auto& schema =
          *std::find_if(r.summary().schemas.begin(), r.summary().schemas.end(), [&](const auto& s) { return s.id == channel.schema_id; });
      EXPECT_EQ(channel.message_encoding, "flatbuffer");
      EXPECT_EQ(schema.encoding, "flatbuffer");
      const auto* reflected = reflection::GetSchema(schema.data.data());
      const auto* root = reflected->objects()->LookupByKey(schema.name.c_str());
      EXPECT_NE(root, nullptr) << schema.name;
      if (root) {
        EXPECT_TRUE(flatbuffers::Verify(*reflected, *root, m.data.data(), m.data.size())) << schema.name;
      }
      if (ch.stream == proto::Stream::force_feedback) {
        std::string why;
        const auto f = proto::decode_force(m.data, &why);
        EXPECT_TRUE(f && std::bit_cast<std::uint64_t>(f->force[2]) == std::bit_cast<std::uint64_t>(session.forces[force_index].force[2]));
        EXPECT_EQ(m.sequence, ++force_index);
      }
      return true;
    });
    EXPECT_EQ(seen[proto::Stream::force_feedback], static_cast<int>(session.forces.size()));
    EXPECT_EQ(seen[proto::Stream::event], 2);
    EXPECT_EQ(seen[proto::Stream::mesh_frame], 2);
    EXPECT_EQ(seen[proto::Stream::instrument_command], 8);

    // The scene's files: attached once each, with their digests; the drops: none.
    ASSERT_EQ(r.scenes().size(), 1u);
    EXPECT_EQ(r.scenes()[0].first_tick, 100u);
    EXPECT_EQ(r.scenes()[0].server_version, "viscera test");
    for (const auto& sent : session.scene_files.files) {
      const auto* f = r.scenes()[0].file(sent.role);
      ASSERT_NE(f, nullptr) << sent.role;
      EXPECT_EQ(f->sha256, sent.sha256);
      EXPECT_EQ(r.attachment(f->attachment), sent.content);
    }
    ASSERT_TRUE(r.drops());
    EXPECT_EQ(r.drops()->count("missing") ? r.drops()->at("missing") : "absent", "0");
  }
  fs::remove_all(dir);
}

TEST(Recording, DropsAreCountedAndWrittenDown) {
  const auto dir = temp_dir("drops");
  const SyntheticSession session;
  session.record(dir / "lossy.mcap", {3, 4, 7});
  Recording r((dir / "lossy.mcap").string());
  ASSERT_TRUE(r.drops());
  EXPECT_EQ(r.drops()->at("missing"), "3");
  fs::remove_all(dir);
}

TEST(Recording, BadFilesGetOneErrorNamingTheFile) {
  const auto dir = temp_dir("bad");
  const SyntheticSession session;
  const auto good = dir / "good.mcap";
  session.record(good);
  const auto bytes = read_bytes(good);

  const auto write = [&](const std::string& name, const std::vector<std::uint8_t>& b) {
    std::ofstream(dir / name, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
    return (dir / name).string();
  };
  const auto error_of = [](const std::string& path) { return what_throws([&] { Recording r(path); }); };

  const auto not_mcap = write("not.mcap", bytes_of("time_s,stress_pa\n0,0\n"));
  EXPECT_NE(error_of(not_mcap).find(not_mcap), std::string::npos) << error_of(not_mcap);

  // Cut short as by a crash, three quarters into its data section (the footer says where the
  // summary starts: 8 bytes at 28 from the end): no summary, and the message says to recover it.
  std::uint64_t summary_start = 0;
  for (int i = 7; i >= 0; --i) summary_start = (summary_start << 8) | bytes[bytes.size() - 28 + static_cast<std::size_t>(i)];
  ASSERT_GT(summary_start, 0u);
  const auto cut = write("cut.mcap", {bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(summary_start * 3 / 4)});
  EXPECT_NE(error_of(cut).find("recover"), std::string::npos) << error_of(cut);
  // Recovered, it reads: every message of its complete chunks, fewer than the whole.
  const auto recovered = (dir / "recovered.mcap").string();
  const auto end = mcap::recover(cut, recovered);
  EXPECT_FALSE(end.complete);
  EXPECT_GT(end.messages, 0u);
  Recording r(recovered);
  EXPECT_EQ(r.summary().statistics->message_count, end.messages);
  EXPECT_LT(end.messages, Recording(good.string()).summary().statistics->message_count);

  // One byte changed inside a chunk: its CRC names the damage.
  auto damaged = bytes;
  damaged[bytes.size() / 3] ^= 0x5a;
  const auto damaged_path = write("damaged.mcap", damaged);
  std::string damaged_error = error_of(damaged_path);
  if (damaged_error.empty()) {  // the summary still reads: the damage shows when the chunk is read
    Recording d(damaged_path);
    damaged_error = what_throws([&] { d.for_each([](const RecordedChannel&, const mcap::Message&) { return true; }); });
  }
  EXPECT_NE(damaged_error.find(damaged_path), std::string::npos) << damaged_error;

  // MCAP, but from a newer viscera, and MCAP, but not viscera's.
  const auto newer = (dir / "newer.mcap").string();
  {
    mcap::McapWriter w(newer);
    w.add_metadata({kRecordingMetadata, {{"schema_version", std::to_string(proto::kSchemaVersion + 1)}}});
  }
  EXPECT_NE(error_of(newer).find("viscera.recording.schema_version"), std::string::npos) << error_of(newer);
  EXPECT_NE(error_of(newer).find("newer"), std::string::npos) << error_of(newer);
  const auto foreign = (dir / "foreign.mcap").string();
  { mcap::McapWriter w(foreign); }
  EXPECT_NE(error_of(foreign).find("not a viscera session recording"), std::string::npos) << error_of(foreign);
  fs::remove_all(dir);
}

TEST(LockstepPlan, PutsEachInputAtTheTickTheServerAppliedIt) {
  const auto dir = temp_dir("plan");
  const SyntheticSession session;
  session.record(dir / "s.mcap");
  Recording r((dir / "s.mcap").string());
  const LockstepPlan plan = make_lockstep_plan(r);
  EXPECT_EQ(plan.first_tick, 100u);
  EXPECT_EQ(plan.last_tick, 110u);
  EXPECT_DOUBLE_EQ(plan.sim_time_s, 0.1);
  std::string why;
  const auto command_seqs = [&](std::uint64_t tick, bool answers) {
    std::vector<std::uint64_t> seqs;
    const auto step = plan.step(tick);
    for (const auto& c : answers ? step.answers : step.commands) seqs.push_back(proto::decode_command(c, &why)->seq);
    return seqs;
  };
  // A command enters a step only when it differs from the one stepped before.
  for (std::uint64_t tick = 100; tick <= 111; ++tick) {
    const bool new_command = tick == 101 || tick == 104 || tick == 108;
    EXPECT_EQ(command_seqs(tick, false).size(), new_command ? 1u : 0u) << "tick " << tick;
  }
  EXPECT_EQ(command_seqs(104, false), std::vector<std::uint64_t>{2});
  // This run's command 2, not the later run's of the same number (told apart by the client stamp).
  EXPECT_EQ(proto::decode_command(plan.step(104).commands.at(0), &why)->tip_position, session.commands[1].tip_position);
  EXPECT_EQ(command_seqs(106, true), std::vector<std::uint64_t>{4});  // answered on the state after tick 105
  // The claim and the material change, where their events say they took effect.
  const auto actions = [&](std::uint64_t tick) {
    std::vector<proto::Action> a;
    for (const auto& q : plan.step(tick).requests) a.push_back(proto::decode_session_request(q, &why)->action);
    return a;
  };
  EXPECT_EQ(actions(100), std::vector<proto::Action>{proto::Action::claim_instrument});
  EXPECT_EQ(actions(106), std::vector<proto::Action>{proto::Action::set_material});
  EXPECT_EQ(*proto::decode_session_request(plan.step(106).requests[0], &why)->material.youngs_modulus_pa, 6000.0);  // not the later run's 9000
  EXPECT_TRUE(plan.step(103).want_frame && plan.step(110).want_frame && !plan.step(104).want_frame);
  EXPECT_EQ(plan.recorded_forces, session.forces.size());
  EXPECT_TRUE(plan.notes.empty()) << plan.notes.front();
  fs::remove_all(dir);
}

TEST(ResimulationCheck, IdenticalResultsPassAndTheFirstChangedBitIsNamed) {
  const auto dir = temp_dir("check");
  const SyntheticSession session;
  session.record(dir / "s.mcap");
  Recording r((dir / "s.mcap").string());
  const LockstepPlan plan = make_lockstep_plan(r);
  {
    ResimulationCheck check(plan, r);
    for (std::uint64_t tick = plan.first_tick; tick <= plan.last_tick; ++tick) check.check(session.result(tick));
    EXPECT_TRUE(check.identical());
    EXPECT_EQ(check.counts().forces_identical, session.forces.size());
    EXPECT_EQ(check.counts().events_identical, 2u);
    EXPECT_EQ(check.counts().frames_identical, 2u);
  }
  {  // one force's z component one unit in the last place off at tick 107; a frame's vertex at 110
    SyntheticSession changed = session;
    changed.forces[6].force[2] = std::nextafter(changed.forces[6].force[2], 1.0);
    changed.frames[1].positions[5] = std::nextafter(changed.frames[1].positions[5], 1.0F);
    ResimulationCheck check(plan, r);
    for (std::uint64_t tick = plan.first_tick; tick <= plan.last_tick; ++tick) check.check(changed.result(tick));
    EXPECT_FALSE(check.identical());
    ASSERT_TRUE(check.first_divergence());
    EXPECT_EQ(check.first_divergence()->tick, 107u);
    EXPECT_EQ(check.first_divergence()->topic, "force_feedback");
    EXPECT_EQ(check.first_divergence()->field, "force.z");
    EXPECT_EQ(check.counts().frames_identical, 1u);
    const auto report = check.report();
    EXPECT_EQ(report.at("first_divergence").at("tick"), 107);
  }
  {  // the material change missing from the re-simulation: the event at tick 106 is named
    ResimulationCheck check(plan, r);
    for (std::uint64_t tick = plan.first_tick; tick <= plan.last_tick; ++tick) {
      auto res = session.result(tick);
      if (tick == 106) res.events.clear();
      check.check(res);
    }
    ASSERT_TRUE(check.first_divergence());
    EXPECT_EQ(check.first_divergence()->tick, 106u);
    EXPECT_EQ(check.first_divergence()->topic, "event");
  }
  fs::remove_all(dir);
}
