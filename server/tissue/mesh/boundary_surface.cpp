#include "viscera/tissue/mesh/boundary_surface.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <map>

namespace viscera::tissue {

BoundarySurface extract_boundary(const TetMesh& mesh) {
  // Outward faces of a positively oriented tet (v0 v1 v2 v3): each face, seen from outside, is
  // counter-clockwise: (1 2 3), (0 3 2), (0 1 3), (0 2 1).
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Entry {
    Triangle oriented;
    std::int32_t tet;
    int count;
  };
  std::map<Triangle, Entry> faces;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Tet& t = mesh.tets[e];
    for (const auto& f : kFaces) {
      const Triangle tri{t[f[0]], t[f[1]], t[f[2]]};
      Triangle key = tri;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key, Entry{tri, static_cast<std::int32_t>(e), 0});
      ++it->second.count;
    }
  }
  BoundarySurface s;
  for (const auto& [key, entry] : faces) {
    if (entry.count != 1) continue;
    s.triangles.push_back(entry.oriented);
    s.owner_tet.push_back(entry.tet);
    s.nodes.insert(s.nodes.end(), entry.oriented.begin(), entry.oriented.end());
  }
  std::sort(s.nodes.begin(), s.nodes.end());
  s.nodes.erase(std::unique(s.nodes.begin(), s.nodes.end()), s.nodes.end());
  return s;
}

}  // namespace viscera::tissue
