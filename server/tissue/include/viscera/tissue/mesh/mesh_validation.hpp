#pragma once  // SPDX-License-Identifier: Apache-2.0
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Shape quality 6 sqrt(2) V / L_rms^3 of a tetrahedron: 1 for the regular one, 0 when flat,
/// negative when inverted.
double tet_quality(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);

/// Tetrahedra with |quality| below this are degenerate (numerically flat).
inline constexpr double kDegenerateQuality = 1e-6;

/// Where a mesh's nodes and tetrahedra came from in its file: the numbers the file gives them and
/// their lines (0: unknown), in the order of TetMesh::nodes and TetMesh::tets.
struct MeshOrigin {
  std::vector<long long> node_ids, element_ids;
  std::vector<long> node_lines, element_lines;
};

/// Throws InputError naming mesh.source and the offending tetrahedron or node for: out-of-range
/// or repeated vertex indices, non-finite coordinates, degenerate, inverted or duplicate
/// tetrahedra, nodes used by no tetrahedron. With `origin`, the message names the element or node
/// by its number in the file and gives its line; without, its 0-based index in the mesh.
void validate_mesh(const TetMesh& mesh, const MeshOrigin* origin = nullptr);

/// Faces shared by more than two tetrahedra: 0 for a mesh of a solid (a cut mesh included).
std::size_t overshared_faces(const TetMesh& mesh);

}  // namespace viscera::tissue
