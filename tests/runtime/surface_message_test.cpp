// The surface on the wire after cuts (surface_message.hpp, schema 16): the liver scene cut by a  // SPDX-License-Identifier: Apache-2.0
// blade as the server cuts it, and after every change of its boundary the patch against what a
// reader holds, applied by the readers' assembler (protocol/surface_assembler.hpp, another code
// path), must give the whole surface the server would have sent, bit for bit; and the patches'
// bytes must be bounded by the change, not the organ.
#include "viscera/runtime/surface_message.hpp"

#include <algorithm>
#include <iostream>

#include <gtest/gtest.h>

#include "viscera/protocol/surface_assembler.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/organ_cutting.hpp"

namespace viscera::runtime {
namespace {

using namespace viscera::tissue;
namespace proto = viscera::protocol;

bool same_surface(const proto::SurfaceTopology& a, const proto::SurfaceTopology& b) {
  return a.mesh_id == b.mesh_id && a.topology_generation == b.topology_generation && a.vertex_count == b.vertex_count && a.triangles == b.triangles &&
         a.rest_positions == b.rest_positions && !a.patch && !b.patch;
}

struct WireRun {
  int changes = 0, patches = 0;
  std::size_t whole_bytes_max = 0, patch_bytes_max = 0, patch_bytes_sum = 0, whole_bytes_sum = 0;
};

/// The scene's organ cut by `strokes` strokes 6 cm long side by side; `every` changes of the surface
/// coalesced per message (the publisher sends at most one per frame).
WireRun cut_and_send(const std::string& scene_file, int strokes, int every) {
  const SceneSpec scene = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_file);
  const std::unique_ptr<Organ> organ = build_organ(scene);
  Organ& o = *organ;
  State s = State::at_rest(*o.mesh);
  proto::SurfaceTopology first = whole_surface(1, 0, scene.name, *o.mesh, o.boundary);
  SentSurface sent{1, 0, o.boundary.nodes, first.triangles};
  proto::SurfaceAssembler reader;
  std::string why0;
  EXPECT_TRUE(reader.take(proto::decode_surface_topology(proto::encode(first), &why0).value()));
  WireRun run;
  const Vec3 mid = 0.5 * (o.bounds.lo + o.bounds.hi);
  const double z = o.bounds.hi.z() - 0.02, blade = 0.02;
  int pending = 0;
  for (int k = 0; k < strokes; ++k) {
    const double y = mid.y() + 0.01 * (k - 0.5 * (strokes - 1));
    for (int i = 0; i < 300; ++i) {
      const double x0 = mid.x() - 0.03 + 0.06 * i / 300, x1 = mid.x() - 0.03 + 0.06 * (i + 1) / 300;
      const BladeSweep sweep{Vec3(x0, y, z), Vec3(x0, y, z + blade), Vec3(x1, y, z), Vec3(x1, y, z + blade)};
      if (!cut_organ(o, sweep, s, k).surface_changed || ++pending < every) continue;
      pending = 0;
      const proto::SurfaceTopology whole = whole_surface(1, o.topology_generation, scene.name, *o.mesh, o.boundary);
      const auto patch = surface_patch(sent, whole, o.boundary.nodes);
      ++run.changes;
      const std::size_t whole_bytes = proto::encode(whole).size();
      run.whole_bytes_max = std::max(run.whole_bytes_max, whole_bytes);
      run.whole_bytes_sum += whole_bytes;
      // What a reader gets goes through the wire's encoding and its checks.
      const auto bytes = proto::encode(patch ? *patch : whole);
      std::string why;
      const auto received = proto::decode_surface_topology(bytes, &why);
      EXPECT_TRUE(received) << why;
      if (!received) return run;
      EXPECT_TRUE(reader.take(*received)) << "change " << run.changes;
      EXPECT_TRUE(same_surface(*reader.surface(), whole)) << "change " << run.changes << (patch ? " (a patch)" : " (whole)");
      if (patch) {
        ++run.patches;
        run.patch_bytes_max = std::max(run.patch_bytes_max, bytes.size());
        run.patch_bytes_sum += bytes.size();
      }
      sent = {1, o.topology_generation, o.boundary.nodes, whole.triangles};
    }
  }
  EXPECT_EQ(reader.patches_skipped(), 0u);
  return run;
}

TEST(SurfaceMessage, PatchesOfTheCutLiverGiveTheWholeSurfaceAndAreBoundedByTheChange) {
  for (const int every : {1, 4}) {
    const WireRun r = cut_and_send("liver.json", 3, every);
    ASSERT_GT(r.changes, 5);
    EXPECT_EQ(r.patches, r.changes);  // every change of a few tetrahedra is smaller as a patch
    EXPECT_LT(r.patch_bytes_max, r.whole_bytes_max / 10);
    std::cout << "[ figure ] 1.5k liver, 3 strokes, " << every << " change(s) per message: " << r.changes << " messages, all patches; patch bytes "
              << r.patch_bytes_sum / std::max(1, r.patches) << " mean, " << r.patch_bytes_max << " max; the whole surface " << r.whole_bytes_max
              << " bytes\n";
  }
}

TEST(SurfaceMessage, OnTheTwelveThousandTetLiverAPatchIsAsSmallAsOnTheCoarseOne) {
  const WireRun coarse = cut_and_send("liver.json", 1, 1), fine = cut_and_send("liver-12k.json", 1, 1);
  ASSERT_GT(fine.patches, 5);
  // Bounded by the cut region: the whole surface is 4x larger at 12k, a patch is not.
  EXPECT_GT(fine.whole_bytes_max, 3 * coarse.whole_bytes_max);
  EXPECT_LT(fine.patch_bytes_sum / fine.patches, 2 * coarse.patch_bytes_sum / std::max(1, coarse.patches));
  std::cout << "[ figure ] one stroke: patch mean " << coarse.patch_bytes_sum / std::max(1, coarse.patches) << " bytes (1.5k), "
            << fine.patch_bytes_sum / fine.patches << " bytes (12k); the whole surface " << coarse.whole_bytes_max << " and " << fine.whole_bytes_max
            << " bytes\n";
}

TEST(SurfaceAssembler, APatchOfAnotherBaseOrOneThatDoesNotFitIsSkippedUntilAWholeSurfaceComes) {
  // A square of two triangles; the patch removes vertex 3 and triangle 1, and inserts a vertex at 1.
  proto::SurfaceTopology whole;
  whole.mesh_id = 2;
  whole.vertex_count = 4;
  whole.rest_positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  whole.triangles = {0, 1, 2, 0, 2, 3};
  proto::SurfaceTopology patch;
  patch.patch = true;
  patch.mesh_id = 2;
  patch.topology_generation = 1;
  patch.vertex_count = 4;
  patch.removed_vertices = {3};
  patch.inserted_vertices = {1};
  patch.rest_positions = {0.5F, 0, 0};
  patch.removed_triangles = {1};
  patch.triangles = {0, 1, 3};
  const proto::SurfaceTopology applied = proto::apply_surface_patch(whole, patch);
  // Kept vertices 0, 1, 2 become 0, 2, 3 around the inserted 1; triangle 0 renumbered, one added.
  EXPECT_EQ(applied.triangles, (std::vector<std::uint32_t>{0, 2, 3, 0, 1, 3}));
  EXPECT_EQ(applied.rest_positions, (std::vector<float>{0, 0, 0, 0.5F, 0, 0, 1, 0, 0, 1, 1, 0}));
  proto::SurfaceAssembler reader;
  EXPECT_FALSE(reader.take(patch));  // no base held: skipped
  EXPECT_TRUE(reader.take(whole));
  proto::SurfaceTopology other = patch;
  other.base_generation = 5;
  EXPECT_FALSE(reader.take(other));
  proto::SurfaceTopology kept_on_removed = patch;
  kept_on_removed.removed_vertices = {2};  // triangle 0 stays on it
  EXPECT_FALSE(reader.take(kept_on_removed));
  EXPECT_THROW(proto::apply_surface_patch(whole, kept_on_removed), std::invalid_argument);
  EXPECT_EQ(reader.patches_skipped(), 3u);
  EXPECT_TRUE(reader.take(patch));
  EXPECT_EQ(reader.surface()->triangles, applied.triangles);
  // A reader of schema 15 refuses a patch: its rest positions do not hold vertex_count vertices.
  // (Checked here on the fields such a reader reads.)
  EXPECT_NE(patch.rest_positions.size(), 3u * patch.vertex_count);
}

}  // namespace
}  // namespace viscera::runtime
