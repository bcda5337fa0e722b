#include "viscera/tissue/mesh/box_mesh.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <stdexcept>

#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

TetMesh make_box_mesh(const Vec3& lo, const Vec3& hi, int nx, int ny, int nz) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("make_box_mesh: need at least one cell");
  TetMesh m;
  m.source = "box mesh";
  const auto id = [&](int i, int j, int k) { return static_cast<std::int32_t>((k * (ny + 1) + j) * (nx + 1) + i); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        m.nodes.emplace_back(lo.x() + (hi.x() - lo.x()) * i / nx, lo.y() + (hi.y() - lo.y()) * j / ny, lo.z() + (hi.z() - lo.z()) * k / nz);
  static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : kPerm) {
          int c[3] = {0, 0, 0};
          Tet t;
          t[0] = id(i, j, k);
          for (int s = 0; s < 3; ++s) {
            c[p[s]] = 1;
            t[s + 1] = id(i + c[0], j + c[1], k + c[2]);
          }
          if (signed_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]) < 0) std::swap(t[2], t[3]);
          m.tets.push_back(t);
        }
  return m;
}

}  // namespace viscera::tissue
