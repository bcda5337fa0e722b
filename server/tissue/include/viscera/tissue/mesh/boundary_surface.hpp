#pragma once  // SPDX-License-Identifier: Apache-2.0
// The boundary of a tetrahedral mesh: faces that belong to exactly one tetrahedron, oriented
// so that (b - a) x (c - a) points out of the mesh.
#include <array>
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

using Triangle = std::array<std::int32_t, 3>;

struct BoundarySurface {
  std::vector<Triangle> triangles;
  std::vector<std::int32_t> owner_tet;  ///< tetrahedron of each triangle
  std::vector<std::int32_t> nodes;  ///< sorted node indices on the boundary
};

BoundarySurface extract_boundary(const TetMesh& mesh);

}  // namespace viscera::tissue
