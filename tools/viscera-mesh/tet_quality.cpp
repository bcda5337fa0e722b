#include "tet_quality.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "viscera/common/percentile.hpp"

namespace viscera::meshing {

TetShape tet_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  const std::array<Eigen::Vector3d, 4> p{a, b, c, d};
  TetShape s;
  s.signed_volume_m3 = (b - a).dot((c - a).cross(d - a)) / 6;
  // Outward normal of the face opposite each vertex.
  std::array<Eigen::Vector3d, 4> n;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& q0 = p[(k + 1) % 4];
    const Eigen::Vector3d& q1 = p[(k + 2) % 4];
    const Eigen::Vector3d& q2 = p[(k + 3) % 4];
    Eigen::Vector3d m = (q1 - q0).cross(q2 - q0);
    if (m.dot(p[k] - q0) > 0) m = -m;
    n[k] = m.normalized();
  }
  s.min_dihedral_deg = 180;
  s.max_dihedral_deg = 0;
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) {
      const double cosine = std::clamp(-n[k].dot(n[l]), -1.0, 1.0);
      const double angle = std::acos(cosine) * 180 / std::numbers::pi;
      s.min_dihedral_deg = std::min(s.min_dihedral_deg, angle);
      s.max_dihedral_deg = std::max(s.max_dihedral_deg, angle);
    }
  double shortest = 1e300;
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) shortest = std::min(shortest, (p[k] - p[l]).norm());
  const Eigen::Vector3d u = b - a, v = c - a, w = d - a;
  const double det = 2 * u.dot(v.cross(w));
  const Eigen::Vector3d centre = (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v)) / det;
  s.radius_edge_ratio = std::isfinite(centre.norm()) ? centre.norm() / shortest : 1e300;
  return s;
}

QualitySummary summarize_quality(const std::vector<Eigen::Vector3d>& nodes, const std::vector<std::array<std::int32_t, 4>>& tets) {
  QualitySummary q;
  q.tets = tets.size();
  if (tets.empty()) return q;
  std::vector<double> smallest, ratio;
  q.min_dihedral_deg = 180;
  for (const auto& t : tets) {
    const TetShape s = tet_shape(nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]);
    const double edge = (nodes[t[0]] - nodes[t[1]]).norm();
    if (s.signed_volume_m3 <= 1e-12 * edge * edge * edge) ++q.inverted_or_flat;
    q.min_dihedral_deg = std::min(q.min_dihedral_deg, s.min_dihedral_deg);
    q.max_dihedral_deg = std::max(q.max_dihedral_deg, s.max_dihedral_deg);
    q.max_radius_edge = std::max(q.max_radius_edge, s.radius_edge_ratio);
    smallest.push_back(s.min_dihedral_deg);
    ratio.push_back(s.radius_edge_ratio);
    ++q.min_dihedral_histogram[std::min<std::size_t>(static_cast<std::size_t>(s.min_dihedral_deg / 5), q.min_dihedral_histogram.size() - 1)];
  }
  q.p1_min_dihedral_deg = common::percentile(smallest, 0.01);
  q.median_radius_edge = common::percentile(ratio, 0.5);
  return q;
}

}  // namespace viscera::meshing
