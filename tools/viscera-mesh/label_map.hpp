#pragma once  // SPDX-License-Identifier: Apache-2.0
// A label map: one integer label per voxel of a 3D image (TotalSegmentator's and 3D Slicer's
// segmentations exported as NIfTI), with the affine that places each voxel centre in the patient's
// space. Read with nifti_clib (NIfTI-1 and NIfTI-2, .nii and .nii.gz); every fault of the file
// is one InputError naming it and the field.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace viscera::meshing {

struct LabelMap {
  std::string source;
  std::array<int, 3> dims{};  ///< voxels along i, j, k
  /// Voxel index (i, j, k) -> patient position [m]: x = affine * (i, j, k, 1), from the sform when
  /// the file has one, else the qform, else the voxel sizes alone. NIfTI's millimetres times 0.001.
  Eigen::Matrix4d affine = Eigen::Matrix4d::Identity();
  std::vector<std::int32_t> labels;  ///< i fastest, then j, then k

  std::int32_t at(int i, int j, int k) const { return labels[(static_cast<std::size_t>(k) * dims[1] + j) * dims[0] + i]; }
  /// Length of the affine's columns: the voxel's edges [m].
  Eigen::Vector3d spacing_m() const;
  double voxel_volume_m3() const;
  /// Voxels of each label present (the background 0 included).
  std::map<std::int32_t, std::int64_t> counts() const;
};

/// Reads a NIfTI label map. Refuses, naming `path` and the field: a file that is not NIfTI, one that
/// is truncated or whose gzip stream is damaged, more than three dimensions of size above 1, a
/// voxel type that is not an integer (or a float holding non-integer values), scaled values, a
/// singular or non-finite affine, and an image of over `max_voxels`.
LabelMap read_label_map(const std::string& path, std::int64_t max_voxels = 512LL * 512 * 1024);

/// "5 (38634 voxels), 4 (1333)..." of the labels present except 0, most voxels first, for messages.
std::string describe_labels(const LabelMap& map, std::size_t at_most = 12);

}  // namespace viscera::meshing
