#pragma once
// A tetrahedral mesh: rest positions (metres) and vertex indices of each tetrahedron,
// positively oriented (signed volume > 0, see element/tet_geometry.hpp).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace viscera::tissue {

using Vec3 = Eigen::Vector3d;
using Tet = std::array<std::int32_t, 4>;

struct TetMesh {
  std::vector<Vec3> nodes;  ///< rest positions [m]
  std::vector<Tet> tets;  ///< vertex indices into nodes
  std::string source;  ///< file (or generator) it came from, for messages

  std::size_t node_count() const { return nodes.size(); }
  std::size_t tet_count() const { return tets.size(); }
};

/// Scales every node position by `factor` about the origin (meshes without units).
void scale_mesh(TetMesh& mesh, double factor);

/// Axis-aligned bounding box of the nodes.
struct Box {
  Vec3 lo, hi;
  bool contains(const Vec3& p) const { return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all(); }
};
Box bounding_box(const TetMesh& mesh);

/// Total volume of the mesh [m^3] (sum of signed tet volumes).
double mesh_volume(const TetMesh& mesh);

/// Mean edge length [m].
double mean_edge_length(const TetMesh& mesh);

}  // namespace viscera::tissue
