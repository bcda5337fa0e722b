// The surface on its way out (mesh_publisher.hpp): after cuts the publisher sends patches only,  // SPDX-License-Identifier: Apache-2.0
// and the whole surface when a reader joins, so that a reader whose history holds nothing but
// patches still assembles the surface; checked by the readers' assembler on what was written.
#include "viscera/runtime/mesh_publisher.hpp"

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "viscera/protocol/surface_assembler.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/organ_cutting.hpp"

namespace viscera::runtime {
namespace {

using namespace viscera::tissue;
namespace proto = viscera::protocol;

/// Keeps what the publisher writes; `readers` is what a DDS writer would count as matched.
struct Recorded final : MeshStream {
  struct Shared {
    std::mutex mutex;
    std::vector<proto::SurfaceTopology> topologies;
    std::atomic<std::uint64_t> readers{1};
  };
  explicit Recorded(Shared& s) : s_(s) {}
  void write_topology(std::uint32_t, std::span<const std::uint8_t> payload) override {
    std::string why;
    const auto t = proto::decode_surface_topology(payload, &why);
    ASSERT_TRUE(t) << why;
    std::lock_guard lock(s_.mutex);
    s_.topologies.push_back(*t);
  }
  void write_frame(std::uint32_t, std::span<const std::uint8_t>) override {}
  std::uint64_t topology_readers_ever() const override { return s_.readers; }
  Shared& s_;
};

TEST(MeshPublisher, AfterACutItSendsPatchesAndTheWholeSurfaceWhenAReaderJoins) {
  const SceneSpec scene = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  const std::unique_ptr<Organ> organ = build_organ(scene);
  Organ& o = *organ;
  State s = State::at_rest(*o.mesh);
  Recorded::Shared wire;
  MeshPublisher publisher(std::make_unique<Recorded>(wire), whole_surface(1, 0, scene.name, *o.mesh, o.boundary), o.boundary.nodes, 1000.0);
  const auto written = [&] {
    std::lock_guard lock(wire.mutex);
    return wire.topologies.size();
  };
  const auto wait_for = [&](std::size_t n) {
    for (int k = 0; k < 2000 && written() < n; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return written() >= n;
  };
  std::int64_t now = 0;
  const auto offer = [&] { publisher.offer(s.x, 0.0, now += 2'000'000, 0); };  // 2 ms later: a frame is due
  ASSERT_EQ(written(), 1u);  // the surface as loaded
  // A stroke: each change of the surface handed over and sent before the next.
  const Vec3 mid = 0.5 * (o.bounds.lo + o.bounds.hi);
  const double z = o.bounds.hi.z() - 0.02;
  int changes = 0;
  for (int i = 0; i < 300 && changes < 8; ++i) {
    const double x0 = mid.x() - 0.03 + 0.06 * i / 300, x1 = mid.x() - 0.03 + 0.06 * (i + 1) / 300;
    if (!cut_organ(o, {Vec3(x0, mid.y(), z), Vec3(x0, mid.y(), z + 0.02), Vec3(x1, mid.y(), z), Vec3(x1, mid.y(), z + 0.02)}, s, 0).surface_changed)
      continue;
    publisher.change_topology(whole_surface(1, o.topology_generation, scene.name, *o.mesh, o.boundary), o.boundary.nodes);
    offer();
    ASSERT_TRUE(wait_for(static_cast<std::size_t>(2 + changes)));
    ++changes;
  }
  ASSERT_EQ(changes, 8);
  {
    std::lock_guard lock(wire.mutex);
    for (std::size_t k = 1; k < wire.topologies.size(); ++k) EXPECT_TRUE(wire.topologies[k].patch) << "message " << k;
  }
  // A reader joins: its history, the last messages, may be patches only; the whole surface as it
  // stands follows at the next frame, and from it and nothing before it the reader has the surface.
  wire.readers = 2;
  offer();
  ASSERT_TRUE(wait_for(static_cast<std::size_t>(2 + changes)));
  proto::SurfaceTopology joined;
  {
    std::lock_guard lock(wire.mutex);
    joined = wire.topologies.back();
  }
  EXPECT_FALSE(joined.patch);
  proto::SurfaceAssembler late;
  {
    std::lock_guard lock(wire.mutex);
    for (std::size_t k = wire.topologies.size() - 4; k < wire.topologies.size(); ++k) late.take(wire.topologies[k]);  // 3 patches, then it
  }
  const proto::SurfaceTopology now_whole = whole_surface(1, o.topology_generation, scene.name, *o.mesh, o.boundary);
  ASSERT_TRUE(late.surface());
  EXPECT_EQ(late.patches_skipped(), 3u);
  EXPECT_EQ(late.surface()->topology_generation, now_whole.topology_generation);
  EXPECT_EQ(late.surface()->triangles, now_whole.triangles);
  EXPECT_EQ(late.surface()->rest_positions, now_whole.rest_positions);
  // No reader joins: frames alone send nothing more; the next change is a patch again.
  offer();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(written(), static_cast<std::size_t>(2 + changes));
  for (int i = 0; i < 300; ++i) {
    const double x0 = mid.x() - 0.03 + 0.06 * i / 300, x1 = mid.x() - 0.03 + 0.06 * (i + 1) / 300, y = mid.y() + 0.01;
    if (!cut_organ(o, {Vec3(x0, y, z), Vec3(x0, y, z + 0.02), Vec3(x1, y, z), Vec3(x1, y, z + 0.02)}, s, 1).surface_changed) continue;
    publisher.change_topology(whole_surface(1, o.topology_generation, scene.name, *o.mesh, o.boundary), o.boundary.nodes);
    offer();
    break;
  }
  ASSERT_TRUE(wait_for(static_cast<std::size_t>(3 + changes)));
  std::lock_guard lock(wire.mutex);
  EXPECT_TRUE(wire.topologies.back().patch);
  EXPECT_TRUE(late.take(wire.topologies.back()));
}

}  // namespace
}  // namespace viscera::runtime
