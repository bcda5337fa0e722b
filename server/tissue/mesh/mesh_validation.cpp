#include "mesh/mesh_validation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "common/input_error.hpp"
#include "element/tet_geometry.hpp"

namespace viscera::tissue {

double tet_quality(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  const std::array<Vec3, 4> x{x0, x1, x2, x3};
  double sum2 = 0.0;
  for (const auto& [a, b] : kTetEdges) sum2 += (x[b] - x[a]).squaredNorm();
  const double l_rms = std::sqrt(sum2 / 6.0);
  return 6.0 * std::sqrt(2.0) * signed_volume(x0, x1, x2, x3) / (l_rms * l_rms * l_rms);
}

void validate_mesh(const TetMesh& mesh) {
  const auto fail = [&](const std::string& what, const std::string& msg) {
    throw InputError(mesh.source, 0, what, msg);
  };
  const auto n = static_cast<std::int64_t>(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    if (!mesh.nodes[i].allFinite()) fail("node " + std::to_string(i), "coordinates are not finite");
  std::vector<char> used(mesh.nodes.size(), 0);
  std::map<std::array<std::int32_t, 4>, std::size_t> seen;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Tet& t = mesh.tets[e];
    const std::string name = "tetrahedron " + std::to_string(e);
    for (int k = 0; k < 4; ++k)
      if (t[k] < 0 || t[k] >= n)
        fail(name, "vertex index " + std::to_string(t[k]) + " is out of range [0, " +
                       std::to_string(n - 1) + "]");
    std::array<std::int32_t, 4> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
      fail(name, "repeats a vertex");
    const auto [it, inserted] = seen.emplace(sorted, e);
    if (!inserted) fail(name, "duplicates tetrahedron " + std::to_string(it->second));
    const double q = tet_quality(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    std::ostringstream qs;
    qs.precision(3);
    qs << q;
    if (!(std::abs(q) >= kDegenerateQuality)) fail(name, "is degenerate (shape quality " + qs.str() + ")");
    if (q < 0) fail(name, "is inverted (negative signed volume, shape quality " + qs.str() + ")");
    for (int k = 0; k < 4; ++k) used[t[k]] = 1;
  }
  for (std::size_t i = 0; i < used.size(); ++i)
    if (!used[i]) fail("node " + std::to_string(i), "is used by no tetrahedron");
}

}  // namespace viscera::tissue
