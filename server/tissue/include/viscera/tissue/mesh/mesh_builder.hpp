#pragma once  // SPDX-License-Identifier: Apache-2.0
// Collects nodes by their file ids and tetrahedra by node ids, then resolves them into a
// TetMesh with contiguous indices, and the
// tetrahedra's group tags into element sets. Used by every reader, so that id errors read the same.
#include <map>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

class MeshBuilder {
 public:
  explicit MeshBuilder(std::string source) : source_(std::move(source)) {}
  /// Adds a node; a repeated id is an error (line is for the message).
  void add_node(long long id, const Vec3& p, long line);
  /// Adds a tetrahedron by node ids; `element` names it in messages (file element id); `groups`:
  /// the tags of the element sets (physical groups) it belongs to.
  void add_tet(const std::array<long long, 4>& ids, long long element, long line, std::span<const int> groups = {});
  /// Names the element set of tag `tag` (Gmsh $PhysicalNames); names of tags no tetrahedron has are dropped.
  void name_group(int tag, std::string name) { group_names_[tag] = std::move(name); }
  /// Resolves ids (an unknown id is an error naming the element), validates, returns the mesh.
  TetMesh build();

 private:
  struct PendingTet {
    std::array<long long, 4> ids;
    long long element;
    long line;
    std::size_t first_group, group_count;  ///< into groups_
  };
  std::string source_;
  std::vector<Vec3> nodes_;
  std::vector<long long> node_ids_;
  std::vector<long> node_lines_;
  std::unordered_map<long long, std::int32_t> index_of_;
  std::vector<PendingTet> tets_;
  std::vector<int> groups_;
  std::map<int, std::string> group_names_;
};

}  // namespace viscera::tissue
