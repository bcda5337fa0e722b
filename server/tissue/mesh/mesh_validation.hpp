#pragma once
#include "mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Shape quality 6 sqrt(2) V / L_rms^3 of a tetrahedron: 1 for the regular one, 0 when flat,
/// negative when inverted.
double tet_quality(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);

/// Tetrahedra with |quality| below this are degenerate (numerically flat).
inline constexpr double kDegenerateQuality = 1e-6;

/// Throws InputError naming mesh.source and the offending tetrahedron (0-based index in the
/// file's order of tetrahedra) or node for: out-of-range or repeated vertex indices, non-finite
/// coordinates, degenerate, inverted or duplicate tetrahedra, nodes used by no tetrahedron.
void validate_mesh(const TetMesh& mesh);

}  // namespace viscera::tissue
