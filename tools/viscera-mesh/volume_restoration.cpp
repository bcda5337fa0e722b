#include "volume_restoration.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>

#include <Eigen/Geometry>

#include "label_fidelity.hpp"

namespace viscera::meshing {

namespace {

bool all_positive(const LabelledMesh& mesh, const std::vector<std::int32_t>& tets) {
  for (const std::int32_t e : tets) {
    const auto& t = mesh.tets[static_cast<std::size_t>(e)];
    const Eigen::Vector3d& a = mesh.nodes[t[0]];
    if ((mesh.nodes[t[1]] - a).dot((mesh.nodes[t[2]] - a).cross(mesh.nodes[t[3]] - a)) <= 0) return false;
  }
  return true;
}

}  // namespace

std::vector<RestoredOffset> restore_label_volumes(LabelledMesh& mesh, const std::vector<VolumeTarget>& targets) {
  std::vector<VolumeTarget> order = targets;
  std::sort(order.begin(), order.end(), [](const VolumeTarget& a, const VolumeTarget& b) { return a.volume_m3 < b.volume_m3; });
  std::vector<RestoredOffset> applied;
  applied.reserve(order.size());
  for (const VolumeTarget& t : order) applied.push_back({t.label, 0});
  // Tetrahedra around each node: what a move must keep positive.
  std::vector<std::vector<std::int32_t>> around(mesh.nodes.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (const std::int32_t v : mesh.tets[e]) around[static_cast<std::size_t>(v)].push_back(static_cast<std::int32_t>(e));
  for (int sweep = 0; sweep < 3; ++sweep)
    for (std::size_t k = 0; k < order.size(); ++k) {
      const auto faces = label_boundary(mesh, {order[k].label});
      // Area-weighted outward normals at the boundary's nodes, and the boundary's area.
      std::vector<Eigen::Vector3d> normal(mesh.nodes.size(), Eigen::Vector3d::Zero());
      double area = 0;
      for (const auto& f : faces) {
        const Eigen::Vector3d n = 0.5 * (mesh.nodes[f[1]] - mesh.nodes[f[0]]).cross(mesh.nodes[f[2]] - mesh.nodes[f[0]]);
        area += n.norm();
        for (const std::int32_t v : f) normal[static_cast<std::size_t>(v)] += n;
      }
      if (area <= 0) continue;
      double offset = (order[k].volume_m3 - label_volume(mesh, order[k].label)) / area;
      std::vector<std::int32_t> moved, touched;
      for (std::size_t v = 0; v < normal.size(); ++v)
        if (normal[v].squaredNorm() > 0) {
          normal[v].normalize();
          moved.push_back(static_cast<std::int32_t>(v));
          touched.insert(touched.end(), around[v].begin(), around[v].end());
        }
      const std::vector<Eigen::Vector3d> before = mesh.nodes;
      for (int tries = 0; tries < 8; ++tries, offset *= 0.5) {
        for (const std::int32_t v : moved)
          mesh.nodes[static_cast<std::size_t>(v)] = before[static_cast<std::size_t>(v)] + offset * normal[static_cast<std::size_t>(v)];
        if (all_positive(mesh, touched)) break;
        mesh.nodes = before;
        if (tries == 7) offset = 0;
      }
      applied[k].offset_m += offset;
    }
  return applied;
}

}  // namespace viscera::meshing
