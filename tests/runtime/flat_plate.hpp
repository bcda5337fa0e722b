#pragma once  // SPDX-License-Identifier: Apache-2.0
// A rigid, finely triangulated plate for the contact tests' closed forms.
#include <cstdint>
#include <vector>

#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::runtime::test {

struct Plate {
  std::vector<tissue::Vec3> x;
  std::vector<tissue::Triangle> triangles;
  /// n x n squares of side h in the plane z = 0, two triangles each, normals +z.
  Plate(int n, double h) {
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) x.emplace_back(i * h - 0.5 * n * h, j * h - 0.5 * n * h, 0.0);
    const auto id = [n](int i, int j) { return static_cast<std::int32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
};

}  // namespace viscera::runtime::test
