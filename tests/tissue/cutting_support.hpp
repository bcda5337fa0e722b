#pragma once  // SPDX-License-Identifier: Apache-2.0
// What the cutting tests check on a cut mesh (cutting_test.cpp, cutting_fuzz_test.cpp).
#include <map>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/tissue/mesh/mesh_validation.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue::test {

// Groups of tetrahedra connected through shared nodes.
inline std::vector<int> node_connected_components(const TetMesh& m, int* count) {
  std::vector<int> parent(m.nodes.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const Tet& t : m.tets)
    for (int k = 1; k < 4; ++k) parent[root(t[k])] = root(t[0]);
  std::vector<int> comp(m.tets.size());
  std::map<int, int> ids;
  for (std::size_t e = 0; e < m.tets.size(); ++e) comp[e] = ids.emplace(root(m.tets[e][0]), static_cast<int>(ids.size())).first->second;
  *count = static_cast<int>(ids.size());
  return comp;
}

// Every face is shared by at most two tetrahedra, and the mesh is valid (positive volumes, no
// unused node, no duplicate tetrahedron).
inline void expect_valid_conforming(const TetMesh& m) {
  ASSERT_NO_THROW(validate_mesh(m));
  ASSERT_EQ(overshared_faces(m), 0u);
}

inline double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

}  // namespace viscera::tissue::test
