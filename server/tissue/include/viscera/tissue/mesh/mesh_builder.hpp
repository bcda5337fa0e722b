#pragma once
// Collects nodes by their file ids and tetrahedra by node ids, then resolves them into a
// TetMesh with contiguous indices. Used by every reader, so that id errors read the same.
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
  /// Adds a tetrahedron by node ids; `element` names it in messages (file element id).
  void add_tet(const std::array<long long, 4>& ids, long long element, long line);
  /// Resolves ids (an unknown id is an error naming the element), validates, returns the mesh.
  TetMesh build();

 private:
  struct PendingTet {
    std::array<long long, 4> ids;
    long long element;
    long line;
  };
  std::string source_;
  std::vector<Vec3> nodes_;
  std::vector<long long> node_ids_;
  std::vector<long> node_lines_;
  std::unordered_map<long long, std::int32_t> index_of_;
  std::vector<PendingTet> tets_;
};

}  // namespace viscera::tissue
