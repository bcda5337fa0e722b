#pragma once  // SPDX-License-Identifier: Apache-2.0
// The tests' own NIfTI-1 writer and reader, byte by byte from the standard's header layout (nifti1.h: 348
// bytes, then 4 bytes of extension flag, the voxels from byte 352), written without the library
// viscera-mesh reads with, so a fault of one is not hidden by the same fault in the other.
// Gzip through zlib when the name ends in .gz.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <zlib.h>

namespace viscera::meshing::test {

struct NiftiImage {
  int nx = 0, ny = 0, nz = 0;
  std::vector<std::uint8_t> labels;  ///< i fastest
  Eigen::Matrix<double, 3, 4> sform = Eigen::Matrix<double, 3, 4>::Zero();  ///< voxel index -> mm
  short datatype = 2;  ///< 2: uint8 (the only type written here)
  short sform_code = 1;
  float scl_slope = 0;
};

inline std::vector<std::uint8_t> nifti_bytes(const NiftiImage& im) {
  std::vector<std::uint8_t> b(352, 0);
  const auto put = [&](std::size_t at, const auto& v) { std::memcpy(b.data() + at, &v, sizeof v); };
  put(0, std::int32_t{348});
  const std::int16_t dim[8] = {3, static_cast<std::int16_t>(im.nx), static_cast<std::int16_t>(im.ny), static_cast<std::int16_t>(im.nz), 1, 1, 1, 1};
  for (int k = 0; k < 8; ++k) put(40 + 2 * static_cast<std::size_t>(k), dim[k]);
  put(70, im.datatype);
  put(72, std::int16_t{8});
  const float pixdim[8] = {
      1, static_cast<float>(im.sform.col(0).norm()), static_cast<float>(im.sform.col(1).norm()), static_cast<float>(im.sform.col(2).norm()), 1, 1, 1,
      1};
  for (int k = 0; k < 8; ++k) put(76 + 4 * static_cast<std::size_t>(k), pixdim[k]);
  put(108, 352.0f);
  put(112, im.scl_slope);
  put(123, std::uint8_t{2});  // millimetres
  put(254, im.sform_code);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) put(280 + 16 * static_cast<std::size_t>(r) + 4 * static_cast<std::size_t>(c), static_cast<float>(im.sform(r, c)));
  std::memcpy(b.data() + 344, "n+1\0", 4);
  b.resize(352 + im.labels.size());
  std::copy(im.labels.begin(), im.labels.end(), b.begin() + 352);
  return b;
}

inline void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0) {
    gzFile f = gzopen(path.c_str(), "wb");
    if (!f || gzwrite(f, bytes.data(), static_cast<unsigned>(bytes.size())) != static_cast<int>(bytes.size()) || gzclose(f) != Z_OK)
      throw std::runtime_error("cannot write " + path);
    return;
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path);
}

inline void write_nifti(const std::string& path, const NiftiImage& im) { write_bytes(path, nifti_bytes(im)); }

/// Reads what write_nifti writes, and TotalSegmentator's uint8 maps: gzip or not, uint8 voxels, the sform.
inline NiftiImage read_nifti_u8(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");  // reads plain files as they are
  if (!f) throw std::runtime_error("cannot open " + path);
  std::vector<std::uint8_t> b;
  std::uint8_t chunk[65536];
  for (int n; (n = gzread(f, chunk, sizeof chunk)) > 0;) b.insert(b.end(), chunk, chunk + n);
  gzclose(f);
  const auto get = [&](std::size_t at, auto v) {
    std::memcpy(&v, b.data() + at, sizeof v);
    return v;
  };
  NiftiImage im;
  im.nx = get(42, std::int16_t{});
  im.ny = get(44, std::int16_t{});
  im.nz = get(46, std::int16_t{});
  im.datatype = get(70, std::int16_t{});
  if (im.datatype != 2) throw std::runtime_error(path + ": not uint8");
  im.sform_code = get(254, std::int16_t{});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) im.sform(r, c) = get(280 + 16 * static_cast<std::size_t>(r) + 4 * static_cast<std::size_t>(c), float{});
  const auto offset = static_cast<std::size_t>(get(108, float{}));
  im.labels.assign(b.begin() + static_cast<std::ptrdiff_t>(offset), b.end());
  if (im.labels.size() != static_cast<std::size_t>(im.nx) * im.ny * im.nz) throw std::runtime_error(path + ": voxel count");
  return im;
}

}  // namespace viscera::meshing::test
