#include "held_faces.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "label_fidelity.hpp"

namespace viscera::meshing {

HeldFaces held_faces(const LabelMap& map, const LabelledMesh& mesh, const std::vector<std::int32_t>& organ_labels, const HoldRequest& request) {
  HeldFaces out;
  std::vector<std::int32_t> owner;
  const auto faces = label_boundary(mesh, organ_labels, &owner);
  const Eigen::Matrix3d lin = map.affine.topLeftCorner<3, 3>();
  const Eigen::Matrix3d inverse = lin.inverse();
  const Eigen::Vector3d shift = map.affine.topRightCorner<3, 1>();
  const Eigen::Vector3d h = map.spacing_m();
  const auto touches = [&](const Eigen::Vector3d& p) {
    if (request.touching.empty()) return false;
    const Eigen::Vector3d q = inverse * (p - shift);
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      const int r = static_cast<int>(std::ceil(request.touch_distance_m / h[a])) + 1;
      lo[a] = std::max(0, static_cast<int>(std::floor(q[a])) - r);
      hi[a] = std::min(map.dims[a] - 1, static_cast<int>(std::ceil(q[a])) + r);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const std::int32_t l = map.at(i, j, k);
          if (std::find(request.touching.begin(), request.touching.end(), l) == request.touching.end()) continue;
          if ((lin * (Eigen::Vector3d(i, j, k) - q)).norm() <= request.touch_distance_m) return true;
        }
    return false;
  };
  const auto on_crop = [&](const Eigen::Vector3d& p) {
    if (!request.crop) return false;
    const Eigen::Vector3d q = inverse * (p - shift);
    for (int a = 0; a < 3; ++a)
      if (q[a] < 0 || q[a] > map.dims[a] - 1) return true;
    return false;
  };
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto& t = faces[f];
    const Eigen::Vector3d c = (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]]) / 3;
    const double area = 0.5 * (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]).norm();
    out.surface_area_m2 += area;
    ++out.surface_faces;
    if (on_crop(c) || touches(c)) {
      ++out.faces;
      out.area_m2 += area;
      out.tets.push_back(owner[f]);
    }
  }
  std::sort(out.tets.begin(), out.tets.end());
  out.tets.erase(std::unique(out.tets.begin(), out.tets.end()), out.tets.end());
  return out;
}

}  // namespace viscera::meshing
