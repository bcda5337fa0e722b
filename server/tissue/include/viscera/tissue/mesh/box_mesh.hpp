#pragma once  // SPDX-License-Identifier: Apache-2.0
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// A structured tetrahedral mesh of the box [lo, hi] with nx x ny x nz cubes, each split into six
/// tetrahedra around its main diagonal (Kuhn subdivision, conforming across cubes).
TetMesh make_box_mesh(const Vec3& lo, const Vec3& hi, int nx, int ny, int nz);

}  // namespace viscera::tissue
