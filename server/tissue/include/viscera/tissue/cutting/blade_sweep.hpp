#pragma once  // SPDX-License-Identifier: Apache-2.0
// The surface a scalpel's blade sweeps between two ticks. The blade is a segment; from (a0, b0)
// at the previous tick to (a1, b1) now it sweeps a bilinear patch, taken as the two triangles
// (a0, b0, b1) and (a0, b1, a1). Between two ticks at 1 kHz the blade moves a fraction of a
// millimetre, so the patch is flat to far below the mesh's resolution.
#include <optional>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

struct BladeSweep {
  Vec3 a0, b0;  ///< blade ends at the previous tick [m]
  Vec3 a1, b1;  ///< blade ends now [m]

  /// Axis-aligned box around the four ends.
  Box bounds() const;
};

/// Where the segment p -> q crosses the swept surface: the parameter s in [0, 1] of the crossing
/// point p + s (q - p), or nothing when it does not cross (or lies in the surface's plane).
std::optional<double> sweep_crossing(const BladeSweep& sweep, const Vec3& p, const Vec3& q);

}  // namespace viscera::tissue
