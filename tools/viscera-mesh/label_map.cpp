#include "label_map.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include <Eigen/LU>
#include <nifti2_io.h>

#include "viscera/common/input_error.hpp"

namespace viscera::meshing {

using common::InputError;

namespace {

struct NiftiFree {
  void operator()(nifti_image* p) const { nifti_image_free(p); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiFree>;

template <typename T>
void copy_labels(const void* data, std::int64_t n, std::vector<std::int32_t>& out, const std::string& path) {
  const T* v = static_cast<const T*>(data);
  out.resize(static_cast<std::size_t>(n));
  for (std::int64_t k = 0; k < n; ++k) {
    const T x = v[k];
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(x) || x != std::round(x) || std::abs(x) > 2'147'483'647.0)
        throw InputError(path, 0, "voxel " + std::to_string(k), common::short_number(static_cast<double>(x)) + " is not an integer label");
    } else if constexpr (sizeof(T) >= 4) {
      if (static_cast<long double>(x) > 2'147'483'647.0L || static_cast<long double>(x) < -2'147'483'648.0L)
        throw InputError(path, 0, "voxel " + std::to_string(k), std::to_string(x) + " is beyond the labels of 32 bits");
    }
    out[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(x);  // NOLINT(bugprone-signed-char-misuse): int8 voxels are signed labels
  }
}

}  // namespace

Eigen::Vector3d LabelMap::spacing_m() const { return affine.topLeftCorner<3, 3>().colwise().norm().transpose(); }

double LabelMap::voxel_volume_m3() const { return std::abs(affine.topLeftCorner<3, 3>().determinant()); }

std::map<std::int32_t, std::int64_t> LabelMap::counts() const {
  std::map<std::int32_t, std::int64_t> c;
  for (const std::int32_t l : labels) ++c[l];
  return c;
}

LabelMap read_label_map(const std::string& path, std::int64_t max_voxels) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(path, 0, "", "no such file");
  if (!std::filesystem::is_regular_file(status)) throw InputError(path, 0, "", "is not a regular file");
  nifti_set_debug_level(0);  // the library's own messages go to stderr; ours name the file and field
  NiftiPtr nim(nifti_image_read(path.c_str(), 0));
  if (!nim) throw InputError(path, 0, "header", "is not a NIfTI-1 or NIfTI-2 image (.nii or .nii.gz): no valid header");
  LabelMap map;
  map.source = path;
  for (int d = 4; d <= 7; ++d)
    if (nim->dim[0] >= d && nim->dim[d] > 1)
      throw InputError(
          path, 0, "dim[" + std::to_string(d) + "]",
          std::to_string(nim->dim[d]) + ": a label map has one value per voxel of a 3D image; this one has a dimension " + std::to_string(d));
  const std::int64_t n[3] = {nim->nx, nim->ny, nim->nz};
  const char* axis[3] = {"dim[1]", "dim[2]", "dim[3]"};
  for (int a = 0; a < 3; ++a) {
    if (n[a] < 1) throw InputError(path, 0, axis[a], std::to_string(n[a]) + " voxels");
    if (n[a] < 2) throw InputError(path, 0, axis[a], "1 voxel: the image is one voxel thick; an organ is meshed from a volume of at least 2 slices");
  }
  if (n[0] * n[1] > max_voxels || n[0] * n[1] * n[2] > max_voxels)
    throw InputError(path, 0, "dim",
                     std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]) + " voxels: more than " +
                         std::to_string(max_voxels) + " (crop the image to the organ)");
  for (int a = 0; a < 3; ++a) map.dims[a] = static_cast<int>(n[a]);
  if (nim->scl_slope != 0 && !(nim->scl_slope == 1 && nim->scl_inter == 0))
    throw InputError(path, 0, "scl_slope",
                     common::short_number(nim->scl_slope) + " (scl_inter " + common::short_number(nim->scl_inter) +
                         "): the values are scaled; a label map stores its labels as they are");
  // The affine, in the order NIfTI's standard gives: sform, qform, voxel sizes.
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity();
  const nifti_dmat44* m = nim->sform_code > 0 ? &nim->sto_xyz : nim->qform_code > 0 ? &nim->qto_xyz : nullptr;
  const char* field = nim->sform_code > 0 ? "srow_x" : nim->qform_code > 0 ? "quatern" : "pixdim";
  if (m) {
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) a(r, c) = m->m[r][c];
  } else {
    for (int k = 0; k < 3; ++k) a(k, k) = nim->pixdim[k + 1];
  }
  double to_m = 1e-3;  // NIfTI's default unit is the millimetre
  if (nim->xyz_units == NIFTI_UNITS_METER) to_m = 1;
  if (nim->xyz_units == NIFTI_UNITS_MICRON) to_m = 1e-6;
  a.topRows<3>() *= to_m;
  const Eigen::Matrix3d l = a.topLeftCorner<3, 3>();
  const double scale = l.colwise().norm().prod();
  if (!a.allFinite() || !(scale > 0) || !(std::abs(l.determinant()) > 1e-6 * scale))
    throw InputError(path, 0, field,
                     "the voxel-to-patient affine is singular or not finite (voxel sizes " + common::short_number(l.col(0).norm() / to_m) + ", " +
                         common::short_number(l.col(1).norm() / to_m) + ", " + common::short_number(l.col(2).norm() / to_m) + "; determinant " +
                         common::short_number(l.determinant() / (to_m * to_m * to_m)) + ")");
  map.affine = a;
  const int type = nim->datatype;
  const bool known = type == NIFTI_TYPE_UINT8 || type == NIFTI_TYPE_INT8 || type == NIFTI_TYPE_INT16 || type == NIFTI_TYPE_UINT16 ||
                     type == NIFTI_TYPE_INT32 || type == NIFTI_TYPE_UINT32 || type == NIFTI_TYPE_INT64 || type == NIFTI_TYPE_UINT64 ||
                     type == NIFTI_TYPE_FLOAT32 || type == NIFTI_TYPE_FLOAT64;
  if (!known)
    throw InputError(path, 0, "datatype",
                     std::to_string(type) + " (" + nifti_datatype_string(type) + ") is not a type of labels (integers, or floats holding integers)");
  if (nifti_image_load(nim.get()) != 0 || !nim->data)
    throw InputError(path, 0, "voxel data",
                     "could not read the " + std::to_string(nim->nvox * nim->nbyper) +
                         " bytes of voxels the header announces: the file is truncated or its gzip stream is damaged");
  const std::int64_t count = n[0] * n[1] * n[2];
  switch (type) {
    case NIFTI_TYPE_UINT8: copy_labels<std::uint8_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_INT8: copy_labels<std::int8_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_INT16: copy_labels<std::int16_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_UINT16: copy_labels<std::uint16_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_INT32: copy_labels<std::int32_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_UINT32: copy_labels<std::uint32_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_INT64: copy_labels<std::int64_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_UINT64: copy_labels<std::uint64_t>(nim->data, count, map.labels, path); break;
    case NIFTI_TYPE_FLOAT32: copy_labels<float>(nim->data, count, map.labels, path); break;
    default: copy_labels<double>(nim->data, count, map.labels, path); break;
  }
  return map;
}

std::string describe_labels(const LabelMap& map, std::size_t at_most) {
  std::vector<std::pair<std::int64_t, std::int32_t>> present;
  for (const auto& [label, n] : map.counts())
    if (label != 0) present.emplace_back(n, label);
  std::sort(present.begin(), present.end(),
            [](const auto& a, const auto& b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
  if (present.empty()) return "none (every voxel is 0)";
  std::string s;
  for (std::size_t k = 0; k < present.size() && k < at_most; ++k)
    s += (k ? ", " : "") + std::to_string(present[k].second) + " (" + std::to_string(present[k].first) + " voxels)";
  if (present.size() > at_most) s += " and " + std::to_string(present.size() - at_most) + " more";
  return s;
}

}  // namespace viscera::meshing
