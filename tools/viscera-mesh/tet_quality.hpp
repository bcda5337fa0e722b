#pragma once  // SPDX-License-Identifier: Apache-2.0
// The shape of tetrahedra as meshing reports it: dihedral angles (a sliver has one near 0 or 180
// degrees and stiffens the explicit step's bound) and the circumradius over the shortest edge
// (sqrt(6)/4 = 0.612 for the regular tetrahedron).
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace viscera::meshing {

struct TetShape {
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  double radius_edge_ratio = 0;
  double signed_volume_m3 = 0;  ///< positive for a positively oriented tetrahedron
};

TetShape tet_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d);

struct QualitySummary {
  std::size_t tets = 0;
  std::size_t inverted_or_flat = 0;  ///< volume <= 1e-12 of the mean edge cubed
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  double p1_min_dihedral_deg = 0;  ///< 1% of the tetrahedra have a smaller smallest angle
  double median_radius_edge = 0, max_radius_edge = 0;
  /// Tetrahedra by their smallest dihedral angle, in bins of 5 degrees from 0 (the last, 70.5 at most).
  std::array<std::size_t, 15> min_dihedral_histogram{};
};

QualitySummary summarize_quality(const std::vector<Eigen::Vector3d>& nodes, const std::vector<std::array<std::int32_t, 4>>& tets);

}  // namespace viscera::meshing
