#pragma once  // SPDX-License-Identifier: Apache-2.0
// The organ's boundary surface brought along a cut in place: only the faces of the tetrahedra the
// cut changed or made are looked at again (their faces before and after), so the work grows with
// the cut region and a pass over the surface's triangles, not with the organ.
#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::tissue {

/// What a cut did to a boundary surface.
struct BoundaryChange {
  std::size_t removed_triangles = 0, added_triangles = 0;
  bool changed() const { return removed_triangles + added_triangles > 0; }
};

/// `surface` (the boundary of the mesh before `change`) becomes the boundary of `cutter.mesh()`:
/// the same faces, oriented outward, as extract_boundary() would give, with the triangles that did
/// not change kept in their order and the new ones after them; nodes stay sorted.
BoundaryChange update_boundary(BoundarySurface& surface, const MeshCutter& cutter, const CutChange& change);

}  // namespace viscera::tissue
