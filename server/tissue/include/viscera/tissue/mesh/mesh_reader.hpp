#pragma once  // SPDX-License-Identifier: Apache-2.0
// Reading tetrahedral meshes: Gmsh .msh (legacy v1, ASCII v2 and v4.1), legacy VTK ASCII
// unstructured grids (.vtk) and ASCII VTU (.vtu). Only linear tetrahedra are volume elements;
// surface and line elements are ignored, other volume elements are an error. Every mesh that is
// returned has passed validate_mesh (mesh_validation.hpp). Errors: InputError naming the file,
// the line (where known) and the field or element.
#include <string>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Reads a mesh, choosing the format from the extension (.msh, .vtk, .vtu).
TetMesh read_tet_mesh(const std::string& path);

TetMesh read_gmsh(const std::string& path);
TetMesh read_legacy_vtk(const std::string& path);
TetMesh read_vtu(const std::string& path);

}  // namespace viscera::tissue
