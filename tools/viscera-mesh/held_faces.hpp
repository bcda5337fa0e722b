#pragma once  // SPDX-License-Identifier: Apache-2.0
// Where a patient's organ is held: the faces of its outer surface that touch given labels of the
// map (the vena cava, a ligament's structure) or lie on a crop plane of the image, where the organ
// went on beyond what was imaged. The server fixes the nodes of these faces (the scene's
// fix_elements names the tetrahedra that own them).
#include <cstdint>
#include <vector>

#include "label_map.hpp"
#include "label_mesher.hpp"

namespace viscera::meshing {

struct HoldRequest {
  std::vector<std::int32_t> touching;  ///< labels whose voxels hold the organ where they touch it
  double touch_distance_m = 0;  ///< a face touches a label when a voxel centre of it lies this close to the face's centroid
  bool crop = false;  ///< hold the faces beyond the image's outermost voxel centres
};

struct HeldFaces {
  std::vector<std::int32_t> tets;  ///< tetrahedra owning a held face, ascending
  std::size_t faces = 0, surface_faces = 0;
  double area_m2 = 0, surface_area_m2 = 0;
};

/// The held faces of the organ made of `organ_labels` in `mesh` (patient space).
HeldFaces held_faces(const LabelMap& map, const LabelledMesh& mesh, const std::vector<std::int32_t>& organ_labels, const HoldRequest& request);

}  // namespace viscera::meshing
