#pragma once  // SPDX-License-Identifier: Apache-2.0
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

/// A set of tetrahedra the mesh file tagged together: a Gmsh physical group of dimension 3 (its
/// tag, and its name from $PhysicalNames if it has one).
struct ElementSet {
  int tag = 0;
  std::string name;
  std::vector<std::int32_t> tets;  ///< indices into TetMesh::tets, ascending
};

struct TetMesh {
  std::vector<Vec3> nodes;  ///< rest positions [m]
  std::vector<Tet> tets;  ///< vertex indices into nodes
  std::string source;  ///< file (or generator) it came from, for messages
  std::vector<ElementSet> element_sets;  ///< tagged sets of tetrahedra, by ascending tag; an element may be in several

  std::size_t node_count() const { return nodes.size(); }
  std::size_t tet_count() const { return tets.size(); }
};

/// The element set of that name or, when `name` is a decimal number, of that tag; nullptr if none.
const ElementSet* find_element_set(const TetMesh& mesh, const std::string& name);
/// The mesh's element sets for messages: "5 'liver', 4 'gallbladder'"; empty when it has none.
std::string describe_element_sets(const TetMesh& mesh);

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
