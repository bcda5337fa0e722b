#include "viscera/tissue/mesh/tet_mesh.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

std::string describe_element_sets(const TetMesh& mesh) {
  std::string known;
  for (const ElementSet& s : mesh.element_sets)
    known += (known.empty() ? "" : ", ") + std::to_string(s.tag) + (s.name.empty() ? "" : " '" + s.name + "'");
  return known;
}

const ElementSet* find_element_set(const TetMesh& mesh, const std::string& name) {
  for (const ElementSet& set : mesh.element_sets)
    if (set.name == name || (!name.empty() && name == std::to_string(set.tag))) return &set;
  return nullptr;
}

void scale_mesh(TetMesh& mesh, double factor) {
  for (auto& p : mesh.nodes) p *= factor;
}

Box bounding_box(const TetMesh& mesh) {
  Box b{Vec3::Constant(std::numeric_limits<double>::infinity()), Vec3::Constant(-std::numeric_limits<double>::infinity())};
  for (const auto& p : mesh.nodes) {
    b.lo = b.lo.cwiseMin(p);
    b.hi = b.hi.cwiseMax(p);
  }
  return b;
}

double mesh_volume(const TetMesh& mesh) {
  double v = 0.0;
  for (const auto& t : mesh.tets) v += signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
  return v;
}

double mean_edge_length(const TetMesh& mesh) {
  double sum = 0.0;
  for (const auto& t : mesh.tets)
    for (const auto& e : kTetEdges) sum += (mesh.nodes[t[e[1]]] - mesh.nodes[t[e[0]]]).norm();
  return mesh.tets.empty() ? 0.0 : sum / (6.0 * static_cast<double>(mesh.tets.size()));
}

}  // namespace viscera::tissue
