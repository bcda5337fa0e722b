#include "viscera/tissue/mesh/mesh_validation.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

#include "viscera/common/input_error.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

using common::InputError;

double tet_quality(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  const std::array<Vec3, 4> x{x0, x1, x2, x3};
  double sum2 = 0.0;
  for (const auto& [a, b] : kTetEdges) sum2 += (x[b] - x[a]).squaredNorm();
  const double l_rms = std::sqrt(sum2 / 6.0);
  return 6.0 * std::sqrt(2.0) * signed_volume(x0, x1, x2, x3) / (l_rms * l_rms * l_rms);
}

void validate_mesh(const TetMesh& mesh, const MeshOrigin* origin) {
  const auto fail = [&](const std::string& what, const std::string& msg, long line = 0) { throw InputError(mesh.source, line, what, msg); };
  const auto known = [](const auto& v, std::size_t k) { return k < v.size(); };
  // The file's own numbers and lines where known.
  const auto element = [&](std::size_t e) {
    return origin && known(origin->element_ids, e) ? "element " + std::to_string(origin->element_ids[e]) : "tetrahedron " + std::to_string(e);
  };
  const auto element_line = [&](std::size_t e) { return origin && known(origin->element_lines, e) ? origin->element_lines[e] : 0L; };
  const auto node = [&](std::size_t i) {
    return origin && known(origin->node_ids, i) ? "node " + std::to_string(origin->node_ids[i]) : "node " + std::to_string(i);
  };
  const auto node_line = [&](std::size_t i) { return origin && known(origin->node_lines, i) ? origin->node_lines[i] : 0L; };
  const auto n = static_cast<std::int64_t>(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    if (!mesh.nodes[i].allFinite()) fail(node(i), "coordinates are not finite", node_line(i));
  std::vector<char> used(mesh.nodes.size(), 0);
  std::map<std::array<std::int32_t, 4>, std::size_t> seen;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Tet& t = mesh.tets[e];
    const std::string name = element(e);
    const long line = element_line(e);
    for (int k = 0; k < 4; ++k)
      if (t[k] < 0 || t[k] >= n)
        fail(name, "vertex index " + common::outside(static_cast<long long>(t[k]), 0LL, static_cast<long long>(n) - 1), line);
    std::array<std::int32_t, 4> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) fail(name, "repeats a vertex", line);
    const auto [it, inserted] = seen.emplace(sorted, e);
    if (!inserted) fail(name, "duplicates " + element(it->second), line);
    const double q = tet_quality(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    std::ostringstream qs;
    qs.precision(3);
    qs << q;
    if (!(std::abs(q) >= kDegenerateQuality)) fail(name, "is degenerate (shape quality " + qs.str() + ")", line);
    if (q < 0) fail(name, "is inverted (negative signed volume, shape quality " + qs.str() + ")", line);
    for (int k = 0; k < 4; ++k) used[t[k]] = 1;
  }
  for (std::size_t i = 0; i < used.size(); ++i)
    if (!used[i]) fail(node(i), "is used by no tetrahedron", node_line(i));
}

std::size_t overshared_faces(const TetMesh& mesh) {
  std::vector<std::array<std::int32_t, 3>> faces;
  faces.reserve(4 * mesh.tets.size());
  for (const Tet& t : mesh.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<std::int32_t, 3> f{};
      int k = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[static_cast<std::size_t>(k++)] = t[static_cast<std::size_t>(i)];
      std::sort(f.begin(), f.end());
      faces.push_back(f);
    }
  std::sort(faces.begin(), faces.end());
  std::size_t count = 0;
  for (std::size_t i = 2; i < faces.size(); ++i) count += faces[i] == faces[i - 2] && (i < 3 || faces[i - 3] != faces[i]);
  return count;
}

}  // namespace viscera::tissue
