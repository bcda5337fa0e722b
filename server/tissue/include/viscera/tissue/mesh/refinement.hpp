#pragma once  // SPDX-License-Identifier: Apache-2.0
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Uniform 1:8 refinement: a node at every edge midpoint, each tetrahedron split into four corner
/// tetrahedra and four from its inner octahedron (cut along the octahedron's shortest diagonal,
/// which keeps the shape quality bounded over repeated refinement). Orientation is preserved;
/// tetrahedron e's children are 8e..8e+7 and keep its element sets.
TetMesh refine_uniform(const TetMesh& mesh);

}  // namespace viscera::tissue
