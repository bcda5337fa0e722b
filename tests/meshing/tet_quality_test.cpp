// The shape measures against their closed forms: the regular tetrahedron and the corner of a cube.  // SPDX-License-Identifier: Apache-2.0
#include "tet_quality.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

using namespace viscera::meshing;
using Eigen::Vector3d;

TEST(TetQuality, TheRegularTetrahedronHasEveryDihedralAngleAcosOneThirdAndRadiusEdgeSqrt6Over4) {
  const Vector3d a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  const double expected = std::acos(1.0 / 3) * 180 / std::numbers::pi;  // 70.53 degrees
  const TetShape s = tet_shape(a, b, c, d);
  EXPECT_NEAR(s.min_dihedral_deg, expected, 1e-9);
  EXPECT_NEAR(s.max_dihedral_deg, expected, 1e-9);
  EXPECT_NEAR(s.radius_edge_ratio, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_NEAR(std::abs(s.signed_volume_m3), std::pow(std::sqrt(8.0), 3) / (6 * std::sqrt(2.0)), 1e-12);
}

TEST(TetQuality, TheCubeCornerHasRightAnglesAtTheCornerAndAcosOneOverSqrt3Elsewhere) {
  const Vector3d o(0, 0, 0), x(2, 0, 0), y(0, 2, 0), z(0, 0, 2);
  const TetShape s = tet_shape(o, x, y, z);
  EXPECT_NEAR(s.max_dihedral_deg, 90, 1e-9);
  EXPECT_NEAR(s.min_dihedral_deg, std::acos(1 / std::sqrt(3.0)) * 180 / std::numbers::pi, 1e-9);  // 54.74
  EXPECT_NEAR(s.radius_edge_ratio, std::sqrt(3.0) / 2, 1e-12);  // circumradius sqrt(3), shortest edge 2
  EXPECT_NEAR(s.signed_volume_m3, 8.0 / 6, 1e-12);
  EXPECT_NEAR(tet_shape(o, y, x, z).signed_volume_m3, -8.0 / 6, 1e-12);
}

TEST(TetQuality, TheSummaryCountsTheInvertedAndFlatAndBinsTheSmallestAngles) {
  const std::vector<Vector3d> nodes{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}};
  const std::vector<std::array<std::int32_t, 4>> tets{{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 1, 4, 2}};  // right, inverted, flat
  const QualitySummary q = summarize_quality(nodes, tets);
  EXPECT_EQ(q.tets, 3U);
  EXPECT_EQ(q.inverted_or_flat, 2U);
  EXPECT_EQ(q.min_dihedral_histogram[10], 2U);  // 54.7 degrees: the bin 50-55, for the tetrahedron and its mirror
}
