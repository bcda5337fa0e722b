// A recording's streams as tables (recording_tables.hpp) without a network: a file written by the  // SPDX-License-Identifier: Apache-2.0
// recorder's writer from messages made here, read back; every column holds what was sent, in
// log-time order, named with its unit; a payload that does not decode is counted, not tabulated;
// frames of one mesh are one array, a frame of another size is dropped and counted.
#include "viscera/recording/recording_tables.hpp"

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/recording/recording_writer.hpp"

namespace fs = std::filesystem;
namespace proto = viscera::protocol;
using namespace viscera::recording;

namespace {

template <class T>
const std::vector<T>& column(const StreamTable& t, const std::string& name) {
  for (const auto& c : t.columns)
    if (c.name == name) return std::get<std::vector<T>>(c.values);
  throw std::runtime_error("no column " + name);
}

struct Written {
  fs::path path;
  std::vector<proto::Force> forces;
  std::vector<proto::MeshFrame> frames;
  proto::SurfaceTopology topology;
};

Written write_session(const std::string& name) {
  Written w;
  w.path = fs::temp_directory_path() / ("viscera_tables_" + name + "_" + std::to_string(::getpid()) + ".mcap");
  RecordingWriter rec(w.path.string(), {0, "", {}, "recording_tables_test"});
  std::uint64_t t = 1'000'000'000;
  const auto add = [&](proto::Stream s, std::uint32_t key, std::uint64_t writer, std::uint64_t seq, const std::vector<std::uint8_t>& payload) {
    rec.add({s, key, seq, static_cast<std::int64_t>(t), writer, payload}, t);
    t += 1'000'000;
  };
  w.topology.mesh_id = 3;
  w.topology.organ_name = "organ";
  w.topology.vertex_count = 3;
  w.topology.triangles = {0, 1, 2};
  w.topology.rest_positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  add(proto::Stream::surface_topology, 3, 1, 1, proto::encode(w.topology));
  for (std::uint64_t k = 1; k <= 5; ++k) {
    proto::Force f;
    f.instrument_id = 2;
    f.client_id = 9;
    f.command_seq = k;
    f.force = {0.1 * static_cast<double>(k), -0.2, 1.5 * static_cast<double>(k)};
    f.in_contact = k % 2 == 0;
    f.stiffness[8] = 100.0 * static_cast<double>(k);
    f.penetration_m = 0.001 * static_cast<double>(k);
    f.tick = 100 + k;
    w.forces.push_back(f);
    add(proto::Stream::force_feedback, 2, 2, k, proto::encode(f));
    proto::MeshFrame m;
    m.mesh_id = 3;
    m.frame = k;
    m.sim_time_s = 0.01 * static_cast<double>(k);
    m.positions = {0, 0, -0.001f * static_cast<float>(k), 1, 0, 0, 0, 1, 0};
    w.frames.push_back(m);
    add(proto::Stream::mesh_frame, 3, 3, k, proto::encode(m));
  }
  proto::MeshFrame wrong = w.frames.back();
  wrong.frame = 6;
  wrong.positions.resize(6);  // two vertices: another mesh size than the topology's
  add(proto::Stream::mesh_frame, 3, 3, 6, proto::encode(wrong));
  add(proto::Stream::force_feedback, 2, 2, 6, {1, 2, 3, 4, 5, 6, 7, 8});  // not a ForceFeedback
  proto::Event e;
  e.kind = proto::EventKind::annotation;
  e.source_client_id = 9;
  e.text = "a note";
  add(proto::Stream::event, 9, 4, 1, proto::encode(e));
  rec.close();
  return w;
}

}  // namespace

TEST(RecordingTables, EveryColumnHoldsWhatWasSentInLogTimeOrder) {
  const Written w = write_session("columns");
  Recording r(w.path.string());
  const RecordingTables t = read_tables(r);
  const StreamTable& forces = t.streams.at("force_feedback");
  ASSERT_EQ(forces.log_time_ns.size(), w.forces.size());
  EXPECT_EQ(forces.undecodable, 1u);
  EXPECT_FALSE(forces.last_error.empty());
  for (std::size_t i = 0; i < w.forces.size(); ++i) {
    EXPECT_EQ(column<double>(forces, "force_x_n")[i], w.forces[i].force[0]);
    EXPECT_EQ(column<double>(forces, "force_z_n")[i], w.forces[i].force[2]);
    EXPECT_EQ(column<std::uint8_t>(forces, "in_contact")[i], w.forces[i].in_contact ? 1 : 0);
    EXPECT_EQ(column<double>(forces, "stiffness_zz_n_per_m")[i], w.forces[i].stiffness[8]);
    EXPECT_EQ(column<double>(forces, "penetration_m")[i], w.forces[i].penetration_m);
    EXPECT_EQ(column<std::uint64_t>(forces, "tick")[i], w.forces[i].tick);
    EXPECT_EQ(column<std::uint64_t>(forces, "sequence")[i], i + 1);
    EXPECT_EQ(column<std::uint64_t>(forces, "source_id")[i], 2u);
    if (i > 0) {
      EXPECT_GT(forces.log_time_ns[i], forces.log_time_ns[i - 1]);
    }
  }
  for (const auto& c : forces.columns)  // every column one value per row
    std::visit([&](const auto& v) { EXPECT_EQ(v.size(), forces.log_time_ns.size()) << c.name; }, c.values);
  const StreamTable& events = t.streams.at("event");
  EXPECT_EQ(column<std::string>(events, "kind"), std::vector<std::string>{"annotation"});
  EXPECT_EQ(column<std::string>(events, "text"), std::vector<std::string>{"a note"});
  // Streams with no message still have their columns.
  const StreamTable& commands = t.streams.at("instrument_command");
  EXPECT_TRUE(commands.log_time_ns.empty());
  EXPECT_NO_THROW(column<double>(commands, "tip_z_m"));
  fs::remove(w.path);
}

TEST(RecordingTables, FramesOfOneMeshAreOneArrayAndAnotherSizeIsCounted) {
  const Written w = write_session("frames");
  Recording r(w.path.string());
  const RecordingTables t = read_tables(r);
  ASSERT_EQ(t.frames.size(), 1u);
  const FrameSeries& s = t.frames.at(3);
  EXPECT_EQ(s.vertex_count, 3u);
  EXPECT_EQ(s.triangles, w.topology.triangles);
  EXPECT_EQ(s.rest_positions, w.topology.rest_positions);
  ASSERT_EQ(s.frame.size(), w.frames.size());
  EXPECT_EQ(s.mismatched, 1u);
  ASSERT_EQ(s.positions.size(), w.frames.size() * 9);
  for (std::size_t k = 0; k < w.frames.size(); ++k) {
    EXPECT_EQ(s.frame[k], w.frames[k].frame);
    EXPECT_EQ(s.sim_time_s[k], w.frames[k].sim_time_s);
    for (std::size_t i = 0; i < 9; ++i) EXPECT_EQ(s.positions[9 * k + i], w.frames[k].positions[i]);
  }
  // Without frames, the frames' metadata is still tabulated.
  const RecordingTables no_frames = read_tables(r, {"mesh_frame"}, false);
  EXPECT_TRUE(no_frames.frames.empty());
  EXPECT_EQ(no_frames.streams.at("mesh_frame").log_time_ns.size(), w.frames.size() + 1);
  fs::remove(w.path);
}

TEST(RecordingTables, AStreamThatIsNotTabulatedIsNamed) {
  const Written w = write_session("names");
  Recording r(w.path.string());
  try {
    read_tables(r, {"lockstep_step"});
    FAIL() << "no error";
  } catch (const viscera::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'lockstep_step' is not one of"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_tables(r, {"forces"}), viscera::common::InputError);
  fs::remove(w.path);
}
