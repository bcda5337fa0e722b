#pragma once  // SPDX-License-Identifier: Apache-2.0
// Tetrahedra in the order of a space-filling curve through their centroids, and nodes numbered in
// the order those tetrahedra last touch them: consecutive elements then share vertices, and the
// nodes of the elements from any one onwards to the end are exactly the highest-numbered ones (so
// the last force chunks write to narrow ranges; docs/PERFORMANCE.md, "Locality").
#include <cstdint>
#include <utility>
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// How a mesh was renumbered: what each new index was before.
struct Renumbering {
  std::vector<std::int32_t> old_node;  ///< old_node[new] = old index
  std::vector<std::int32_t> old_tet;  ///< old_tet[new] = old index
};

/// The same mesh (the same tetrahedra, each with its vertices in the same order, so the same
/// orientation; the same element sets), renumbered: tetrahedra along a Hilbert curve through
/// their centroids, nodes in the order the reordered tetrahedra last name them (nodes no
/// tetrahedron names keep their relative order, after the others). Deterministic.
TetMesh ordered_for_locality(const TetMesh& mesh, Renumbering* renumbering = nullptr);

/// The node indices tetrahedra [first, last) name lie in [lo, hi): {smallest, largest + 1}, or
/// {0, 0} for no tetrahedra.
std::pair<std::int32_t, std::int32_t> node_range(const TetMesh& mesh, std::size_t first, std::size_t last);

}  // namespace viscera::tissue
