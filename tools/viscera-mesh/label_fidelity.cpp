#include "label_fidelity.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "viscera/common/percentile.hpp"

namespace viscera::meshing {

std::vector<std::array<std::int32_t, 3>> label_boundary(const LabelledMesh& mesh, const std::vector<std::int32_t>& labels,
                                                        std::vector<std::int32_t>* owner) {
  const auto in = [&](std::int32_t l) { return std::find(labels.begin(), labels.end(), l) != labels.end(); };
  // Each face by its sorted vertices: the tetrahedra on its sides.
  std::map<std::array<std::int32_t, 3>, std::array<std::int32_t, 2>> sides;
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};  // outward for a positive tetrahedron
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (const auto& f : kFace) {
      std::array<std::int32_t, 3> key{mesh.tets[e][f[0]], mesh.tets[e][f[1]], mesh.tets[e][f[2]]};
      std::sort(key.begin(), key.end());
      auto [it, inserted] = sides.emplace(key, std::array<std::int32_t, 2>{static_cast<std::int32_t>(e), -1});
      if (!inserted) it->second[1] = static_cast<std::int32_t>(e);
    }
  std::vector<std::array<std::int32_t, 3>> out;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    if (!in(mesh.label[e])) continue;
    for (const auto& f : kFace) {
      std::array<std::int32_t, 3> tri{mesh.tets[e][f[0]], mesh.tets[e][f[1]], mesh.tets[e][f[2]]};
      std::array<std::int32_t, 3> key = tri;
      std::sort(key.begin(), key.end());
      const auto& s = sides.at(key);
      const std::int32_t other = s[0] == static_cast<std::int32_t>(e) ? s[1] : s[0];
      if (other >= 0 && in(mesh.label[static_cast<std::size_t>(other)])) continue;
      out.push_back(tri);
      if (owner) owner->push_back(static_cast<std::int32_t>(e));
    }
  }
  return out;
}

LabelBoundaryDistance::LabelBoundaryDistance(const LabelMap& map, std::int32_t label)
    : map_(map), lin_(map.affine.topLeftCorner<3, 3>()), inverse_(lin_.inverse()), shift_(map.affine.topRightCorner<3, 1>()) {
  const auto& n = map.dims;
  bucket_.resize(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (map.at(i, j, k) != label) continue;
        const std::array<int, 3> v{i, j, k};
        for (int a = 0; a < 3; ++a)
          for (int side = -1; side <= 1; side += 2) {
            std::array<int, 3> w = v;
            w[a] += side;
            const bool outside = w[a] < 0 || w[a] >= n[a];
            if (!outside && map.at(w[0], w[1], w[2]) == label) continue;
            bucket_[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i].push_back(static_cast<std::int32_t>(faces_.size()));
            faces_.push_back({v, a, side});
          }
      }
}

double LabelBoundaryDistance::to_face(const Eigen::Vector3d& q, const Face& f) const {
  // The face is a rectangle in index space; with an affine that is a rotation times the voxel sizes,
  // clamping each index coordinate gives the nearest point in the patient's metric too.
  Eigen::Vector3d c;
  for (int a = 0; a < 3; ++a) {
    if (a == f.axis)
      c[a] = f.voxel[a] + 0.5 * f.side;
    else
      c[a] = std::clamp(q[a], f.voxel[a] - 0.5, f.voxel[a] + 0.5);
  }
  return (lin_ * (c - q)).norm();
}

double LabelBoundaryDistance::operator()(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = inverse_ * (p - shift_);
  const auto& n = map_.dims;
  const Eigen::Vector3d h = map_.spacing_m();
  double best = 1e300;
  // Voxels within a growing box around q; stop once the box's margin exceeds the best distance.
  for (int r = 1;; r *= 2) {
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int>(std::floor(q[a])) - r);
      hi[a] = std::min(n[a] - 1, static_cast<int>(std::ceil(q[a])) + r);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i)
          for (const std::int32_t f : bucket_[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i]) best = std::min(best, to_face(q, faces_[f]));
    const bool whole = lo == std::array<int, 3>{0, 0, 0} && hi == std::array<int, 3>{n[0] - 1, n[1] - 1, n[2] - 1};
    if (best <= (r - 0.5) * h.minCoeff() || whole) return best;
  }
}

double label_volume(const LabelledMesh& mesh, std::int32_t label) {
  double v = 0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    if (mesh.label[e] != label) continue;
    const auto& t = mesh.tets[e];
    const Eigen::Vector3d& a = mesh.nodes[t[0]];
    v += (mesh.nodes[t[1]] - a).dot((mesh.nodes[t[2]] - a).cross(mesh.nodes[t[3]] - a)) / 6;
  }
  return v;
}

LabelFidelity label_fidelity(const LabelMap& map, const LabelledMesh& mesh, std::int32_t label) {
  LabelFidelity f;
  f.label = label;
  f.tets = static_cast<std::size_t>(std::count(mesh.label.begin(), mesh.label.end(), label));
  f.mesh_volume_m3 = label_volume(mesh, label);
  const auto counts = map.counts();
  const auto it = counts.find(label);
  f.voxel_volume_m3 = it == counts.end() ? 0 : static_cast<double>(it->second) * map.voxel_volume_m3();
  const LabelBoundaryDistance distance(map, label);
  std::vector<double> d;
  std::vector<char> seen(mesh.nodes.size(), 0);
  for (const auto& tri : label_boundary(mesh, {label})) {
    for (const std::int32_t v : tri)
      if (!seen[static_cast<std::size_t>(v)]) {
        seen[static_cast<std::size_t>(v)] = 1;
        d.push_back(distance(mesh.nodes[static_cast<std::size_t>(v)]));
      }
    d.push_back(distance((mesh.nodes[tri[0]] + mesh.nodes[tri[1]] + mesh.nodes[tri[2]]) / 3));
  }
  f.surface_samples = d.size();
  if (!d.empty()) {
    double sum = 0;
    for (const double x : d) sum += x;
    f.distance_mean_m = sum / static_cast<double>(d.size());
    f.distance_p95_m = common::percentile(d, 0.95);
    f.distance_max_m = *std::max_element(d.begin(), d.end());
  }
  return f;
}

}  // namespace viscera::meshing
