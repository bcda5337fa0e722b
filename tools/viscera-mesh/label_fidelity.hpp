#pragma once  // SPDX-License-Identifier: Apache-2.0
// How faithfully a labelled mesh follows its label map: each label's mesh volume against its
// voxels' volume, and the distance from the label's mesh surface (its boundary faces, the
// interfaces with other labels included) to the label's boundary in the image (the voxel faces
// between the label and any other value).
#include <array>
#include <cstdint>
#include <vector>

#include "label_map.hpp"
#include "label_mesher.hpp"

namespace viscera::meshing {

/// The faces of `tets` (vertex triples, oriented outward) whose tetrahedron's label is in `labels`
/// and whose other side is not: a label's boundary when `labels` is one label, the organ's outer
/// surface when it is all of them. `owner` gets each face's tetrahedron.
std::vector<std::array<std::int32_t, 3>> label_boundary(const LabelledMesh& mesh, const std::vector<std::int32_t>& labels,
                                                        std::vector<std::int32_t>* owner = nullptr);

/// The volume of the tetrahedra of `label` [m^3].
double label_volume(const LabelledMesh& mesh, std::int32_t label);

struct LabelFidelity {
  std::int32_t label = 0;
  std::size_t tets = 0;
  double mesh_volume_m3 = 0, voxel_volume_m3 = 0;
  std::size_t surface_samples = 0;  ///< the boundary faces' vertices and centroids measured
  double distance_mean_m = 0, distance_p95_m = 0, distance_max_m = 0;  ///< to the label's voxel boundary
};

LabelFidelity label_fidelity(const LabelMap& map, const LabelledMesh& mesh, std::int32_t label);

/// Distance from `p` [m, patient space] to the boundary of `label` in `map` (the voxel faces
/// between the label and another value, the image's border counting as another value).
class LabelBoundaryDistance {
 public:
  LabelBoundaryDistance(const LabelMap& map, std::int32_t label);
  double operator()(const Eigen::Vector3d& p) const;

 private:
  struct Face {
    std::array<int, 3> voxel;  ///< the label's voxel
    int axis, side;  ///< the face is at voxel[axis] + side/2 (side -1 or +1)
  };
  double to_face(const Eigen::Vector3d& q, const Face& f) const;
  const LabelMap& map_;
  Eigen::Matrix3d lin_;
  Eigen::Matrix3d inverse_;
  Eigen::Vector3d shift_;
  std::vector<Face> faces_;
  std::vector<std::vector<std::int32_t>> bucket_;  ///< faces by voxel
};

}  // namespace viscera::meshing
