// The locality order (mesh/locality_order.hpp) against the mesh it renumbers: the same tetrahedra  // SPDX-License-Identifier: Apache-2.0
// on the same points with the same orientation and element sets, deterministic and idempotent;
// and what it does, against the order it replaces and a shuffled one: consecutive tetrahedra are
// neighbours, and the nodes of a contiguous range of them (a force chunk) lie in a narrower range,
// the last chunk's in exactly its own.
#include "viscera/tissue/mesh/locality_order.hpp"

#include <algorithm>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/refinement.hpp"

using namespace viscera::tissue;

namespace {

TetMesh liver_12k() {
  TetMesh m = refine_uniform(read_tet_mesh(std::string(VISCERA_DATA_DIR) + "/meshes/liver2.msh"));
  scale_mesh(m, 0.08);
  return m;
}

/// The widths of the node ranges of chunks 1 .. chunks-1 of `chunks` equal ranges of tetrahedra
/// (those with a buffer of their own in ParallelForces; chunk 0 adds to the forces directly),
/// summed, per node.
double range_per_node(const TetMesh& m, std::size_t chunks) {
  double sum = 0.0;
  for (std::size_t c = 1; c < chunks; ++c) {
    const auto [lo, hi] = node_range(m, m.tet_count() * c / chunks, m.tet_count() * (c + 1) / chunks);
    sum += hi - lo;
  }
  return sum / static_cast<double>(m.node_count());
}

}  // namespace

TEST(LocalityOrder, RenumbersTheSameTetrahedraWithTheirOrientationAndSets) {
  TetMesh m = make_box_mesh(Vec3(0, 0, 0), Vec3(0.1, 0.02, 0.03), 10, 2, 3);
  m.nodes.push_back(Vec3(1, 1, 1));  // a node no tetrahedron names: kept, after the others
  m.element_sets.push_back({4, "front", {0, 5, 17, 200}});
  m.element_sets.push_back({9, "", {3}});
  Renumbering r;
  const TetMesh o = ordered_for_locality(m, &r);
  ASSERT_EQ(o.tet_count(), m.tet_count());
  ASSERT_EQ(o.node_count(), m.node_count());
  ASSERT_EQ(r.old_tet.size(), m.tet_count());
  ASSERT_EQ(r.old_node.size(), m.node_count());
  // Permutations, positions carried.
  EXPECT_EQ(std::set<std::int32_t>(r.old_tet.begin(), r.old_tet.end()).size(), m.tet_count());
  EXPECT_EQ(std::set<std::int32_t>(r.old_node.begin(), r.old_node.end()).size(), m.node_count());
  for (std::size_t v = 0; v < o.node_count(); ++v) EXPECT_EQ(o.nodes[v], m.nodes[static_cast<std::size_t>(r.old_node[v])]);
  EXPECT_EQ(r.old_node.back(), static_cast<std::int32_t>(m.node_count() - 1));
  // Each tetrahedron has the same points in the same order: the same signed volume.
  for (std::size_t e = 0; e < o.tet_count(); ++e) {
    const Tet& before = m.tets[static_cast<std::size_t>(r.old_tet[e])];
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(o.nodes[static_cast<std::size_t>(o.tets[e][k])], m.nodes[static_cast<std::size_t>(before[k])]) << "tet " << e;
    const auto& x = o.nodes;
    EXPECT_GT(signed_volume(x[o.tets[e][0]], x[o.tets[e][1]], x[o.tets[e][2]], x[o.tets[e][3]]), 0.0);
  }
  EXPECT_NEAR(mesh_volume(o), mesh_volume(m), 1e-15);
  // The element sets name the same tetrahedra, ascending.
  ASSERT_EQ(o.element_sets.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_EQ(o.element_sets[s].tag, m.element_sets[s].tag);
    EXPECT_EQ(o.element_sets[s].name, m.element_sets[s].name);
    std::vector<std::int32_t> back;
    for (const std::int32_t e : o.element_sets[s].tets) back.push_back(r.old_tet[static_cast<std::size_t>(e)]);
    std::sort(back.begin(), back.end());
    EXPECT_EQ(back, m.element_sets[s].tets);
    EXPECT_TRUE(std::is_sorted(o.element_sets[s].tets.begin(), o.element_sets[s].tets.end()));
  }
  // No tetrahedra, or every point in one place: nodes kept, nothing divided by a zero extent.
  TetMesh empty;
  empty.nodes = {Vec3(1, 2, 3), Vec3(1, 2, 3)};
  EXPECT_EQ(ordered_for_locality(empty).nodes, empty.nodes);
  TetMesh flat;
  flat.nodes.assign(4, Vec3(0.5, 0.5, 0.5));
  flat.tets = {{0, 1, 2, 3}, {3, 2, 1, 0}};
  EXPECT_EQ(ordered_for_locality(flat).tet_count(), 2u);
  EXPECT_EQ(node_range(empty, 0, 0), (std::pair<std::int32_t, std::int32_t>{0, 0}));
  // Deterministic, and an ordered mesh is already in order.
  const TetMesh again = ordered_for_locality(m), twice = ordered_for_locality(o);
  EXPECT_EQ(again.tets, o.tets);
  EXPECT_EQ(twice.tets, o.tets);
  EXPECT_EQ(twice.nodes, o.nodes);
}

TEST(LocalityOrder, ConsecutiveTetrahedraAreNeighboursAndChunksTouchNarrowerRangesOfNodes) {
  const TetMesh refined = liver_12k();
  const TetMesh ordered = ordered_for_locality(refined);
  // Along the curve, the next tetrahedron's centroid is about an element away; a shuffled order
  // jumps across the organ.
  const auto mean_step = [](const TetMesh& m) {
    double sum = 0.0;
    const auto centroid = [&](std::size_t e) {
      Vec3 c = Vec3::Zero();
      for (const std::int32_t v : m.tets[e]) c += 0.25 * m.nodes[static_cast<std::size_t>(v)];
      return c;
    };
    for (std::size_t e = 1; e < m.tet_count(); ++e) sum += (centroid(e) - centroid(e - 1)).norm();
    return sum / static_cast<double>(m.tet_count() - 1);
  };
  TetMesh shuffled = refined;
  std::mt19937 rng(3);
  std::shuffle(shuffled.tets.begin(), shuffled.tets.end(), rng);
  const double h = mean_edge_length(refined);
  std::printf("[ figure ] 12k liver: consecutive centroids %.2f mean edge lengths apart ordered, %.2f shuffled\n", mean_step(ordered) / h,
              mean_step(shuffled) / h);
  EXPECT_LT(mean_step(ordered), 1.0 * h);
  EXPECT_GT(mean_step(shuffled), 5.0 * h);
  for (const std::size_t chunks : {2u, 8u, 64u}) {
    // Nodes numbered as last touched: the tetrahedra from a chunk's start to the end name exactly
    // the nodes from its range's start up, counted here independently.
    std::set<std::int32_t> seen;
    for (std::size_t c = chunks; c-- > 0;) {
      const std::size_t first = ordered.tet_count() * c / chunks, last = ordered.tet_count() * (c + 1) / chunks;
      for (std::size_t e = first; e < last; ++e) seen.insert(ordered.tets[e].begin(), ordered.tets[e].end());
      const auto [lo, hi] = node_range(ordered, first, last);
      EXPECT_EQ(ordered.node_count() - static_cast<std::size_t>(lo), seen.size()) << "chunk " << c << " of " << chunks;
      if (c == chunks - 1) EXPECT_EQ(static_cast<std::size_t>(hi), ordered.node_count());
    }
    const double before = range_per_node(refined, chunks), after = range_per_node(ordered, chunks);
    std::printf("[ figure ] 12k liver, %zu chunks: node ranges cover %.2f x the nodes in the refined order, %.2f x ordered\n", chunks, before, after);
    // A chunk's range reaches up to its border with the chunks after it, which a Hilbert curve
    // does not keep near its start; the last chunk's is exactly its own nodes. The refined order
    // numbers every corner node before every edge midpoint: each chunk spans nearly all.
    EXPECT_LT(after, 0.7 * before) << chunks << " chunks";
  }
}
