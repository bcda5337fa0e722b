#pragma once  // SPDX-License-Identifier: Apache-2.0
// A surface meshed from voxels cuts the corners of their steps: a convex label loses volume in
// proportion to its voxel size over its radius (4% for a 13 mm sphere on 2 mm voxels). Each label's
// boundary nodes are moved along the label's outward normal by the uniform offset that gives back
// the label's voxel volume (its deficit over its boundary's area, a fraction of a millimetre);
// interfaces move with the smaller label, so the larger one gives up what the smaller gains.
#include <cstdint>
#include <vector>

#include "label_mesher.hpp"

namespace viscera::meshing {

struct VolumeTarget {
  std::int32_t label = 0;
  double volume_m3 = 0;
};

struct RestoredOffset {
  std::int32_t label = 0;
  double offset_m = 0;  ///< the sum of the offsets applied, positive outward
};

/// Moves the nodes of `mesh` in place; labels in `targets` are treated smallest first, three
/// sweeps. An offset that would invert a tetrahedron is halved until none is (or given up).
std::vector<RestoredOffset> restore_label_volumes(LabelledMesh& mesh, const std::vector<VolumeTarget>& targets);

}  // namespace viscera::meshing
