#pragma once
// Tetrahedra in the order of a space-filling curve through their centroids, and nodes numbered in
// the order those tetrahedra first touch them: consecutive elements then share vertices, and the
// nodes a range of elements touches lie in a narrow range of indices (docs/PERFORMANCE.md,
// "Locality").
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
/// their centroids, nodes in the order the reordered tetrahedra first name them (nodes no
/// tetrahedron names keep their relative order, after the others). Deterministic.
TetMesh ordered_for_locality(const TetMesh& mesh, Renumbering* renumbering = nullptr);

/// The node indices tetrahedra [first, last) name lie in [lo, hi): {smallest, largest + 1}, or
/// {0, 0} for no tetrahedra.
std::pair<std::int32_t, std::int32_t> node_range(const TetMesh& mesh, std::size_t first, std::size_t last);

}  // namespace viscera::tissue
