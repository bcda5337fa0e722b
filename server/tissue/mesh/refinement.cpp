#include "viscera/tissue/mesh/refinement.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <unordered_map>

#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

TetMesh refine_uniform(const TetMesh& mesh) {
  TetMesh out;
  out.source = mesh.source + " (refined 1:8)";
  out.nodes = mesh.nodes;
  std::unordered_map<std::uint64_t, std::int32_t> midpoint;
  const auto mid = [&](std::int32_t a, std::int32_t b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
    const auto [it, inserted] = midpoint.try_emplace(key, static_cast<std::int32_t>(out.nodes.size()));
    if (inserted) out.nodes.push_back(0.5 * (mesh.nodes[a] + mesh.nodes[b]));
    return it->second;
  };
  const auto add = [&](Tet t) {
    if (signed_volume(out.nodes[t[0]], out.nodes[t[1]], out.nodes[t[2]], out.nodes[t[3]]) < 0) std::swap(t[2], t[3]);
    out.tets.push_back(t);
  };
  out.tets.reserve(8 * mesh.tets.size());
  for (const Tet& t : mesh.tets) {
    const std::int32_t m01 = mid(t[0], t[1]), m02 = mid(t[0], t[2]), m03 = mid(t[0], t[3]);
    const std::int32_t m12 = mid(t[1], t[2]), m13 = mid(t[1], t[3]), m23 = mid(t[2], t[3]);
    out.tets.push_back({t[0], m01, m02, m03});
    out.tets.push_back({m01, t[1], m12, m13});
    out.tets.push_back({m02, m12, t[2], m23});
    out.tets.push_back({m03, m13, m23, t[3]});
    // The octahedron's three diagonals and, for each, its ring of four vertices in cyclic order.
    const std::int32_t diag[3][2] = {{m01, m23}, {m02, m13}, {m03, m12}};
    const std::int32_t ring[3][4] = {{m02, m12, m13, m03}, {m01, m12, m23, m03}, {m01, m02, m23, m13}};
    int best = 0;
    double best_len = 1e300;
    for (int d = 0; d < 3; ++d) {
      const double len = (out.nodes[diag[d][0]] - out.nodes[diag[d][1]]).squaredNorm();
      if (len < best_len) {
        best_len = len;
        best = d;
      }
    }
    for (int k = 0; k < 4; ++k) add({diag[best][0], diag[best][1], ring[best][k], ring[best][(k + 1) % 4]});
  }
  // Tetrahedron e's eight children are 8e..8e+7: each keeps its parent's element sets.
  for (const ElementSet& set : mesh.element_sets) {
    ElementSet& child = out.element_sets.emplace_back(ElementSet{set.tag, set.name, {}});
    child.tets.reserve(8 * set.tets.size());
    for (const std::int32_t e : set.tets)
      for (std::int32_t c = 0; c < 8; ++c) child.tets.push_back(8 * e + c);
  }
  return out;
}

}  // namespace viscera::tissue
