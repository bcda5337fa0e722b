#pragma once
// Loads and constraints shared by the integrators: lumped masses, gravity, fixed nodes and nodes
// whose position is prescribed as a function of rest position and time.
#include <functional>
#include <span>
#include <vector>

#include "mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Lumped nodal masses [kg]: each tetrahedron gives a quarter of rho V to each vertex.
std::vector<double> lumped_masses(const TetMesh& mesh, std::span<const double> density_kg_m3);
std::vector<double> lumped_masses(const TetMesh& mesh, double density_kg_m3);

struct PrescribedMotion {
  std::vector<std::int32_t> nodes;
  /// Position [m] of a node with rest position X at time t [s].
  std::function<Vec3(const Vec3& rest, double t)> position;
};

struct BoundaryConditions {
  Vec3 gravity_m_s2 = Vec3::Zero();
  std::vector<std::int32_t> fixed_nodes;        ///< held at their rest positions
  std::vector<PrescribedMotion> prescribed;     ///< moved as prescribed
  /// Constant external forces [N] per node (empty = none).
  std::vector<Vec3> nodal_forces;

  /// 1 for nodes that are fixed or prescribed, else 0.
  std::vector<char> constrained_mask(std::size_t node_count) const;
};

/// Node selections for fixed regions.
std::vector<std::int32_t> nodes_in_box(const TetMesh& mesh, const Box& box);
/// Boundary-surface nodes inside the box.
std::vector<std::int32_t> surface_nodes_in_box(const TetMesh& mesh, const Box& box);

}  // namespace viscera::tissue
