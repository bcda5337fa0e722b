// Label maps read through nifti_clib against files the test writes byte by byte (nifti_file.hpp),  // SPDX-License-Identifier: Apache-2.0
// and each fault of a file named with the file and the field.
#include "label_map.hpp"

#include <filesystem>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"

#include "nifti_file.hpp"

using namespace viscera::meshing;
using viscera::common::InputError;
using viscera::meshing::test::NiftiImage;

namespace {

std::string tmp(const std::string& name) {
  std::filesystem::create_directories(VISCERA_TEST_TMP);
  return std::string(VISCERA_TEST_TMP) + "/" + name;
}

/// 6 x 5 x 4 voxels of 1.5 x 2 x 3 mm, turned 30 degrees about z and moved; label = i + 10 j + 50 k % 200.
NiftiImage small_image() {
  NiftiImage im;
  im.nx = 6, im.ny = 5, im.nz = 4;
  for (int k = 0; k < im.nz; ++k)
    for (int j = 0; j < im.ny; ++j)
      for (int i = 0; i < im.nx; ++i) im.labels.push_back(static_cast<std::uint8_t>((i + 10 * j + 50 * k) % 200));
  const Eigen::Matrix3d r = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  im.sform.leftCols<3>() = r * Eigen::Vector3d(1.5, 2, 3).asDiagonal();
  im.sform.col(3) = Eigen::Vector3d(-100, 20, 300);
  return im;
}

std::string error_of(const std::string& path) {
  try {
    read_label_map(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(LabelMap, ReadsTheVoxelsAndTheAffineInMetresPlainAndGzipped) {
  const NiftiImage im = small_image();
  for (const std::string name : {"small.nii", "small.nii.gz"}) {
    test::write_nifti(tmp(name), im);
    const LabelMap map = read_label_map(tmp(name));
    ASSERT_EQ(map.dims, (std::array<int, 3>{6, 5, 4}));
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 6; ++i) EXPECT_EQ(map.at(i, j, k), (i + 10 * j + 50 * k) % 200);
    // Voxel (2, 3, 1) lies where the sform puts it, in metres (the header's floats: 1e-7 relative).
    const Eigen::Vector4d v(2, 3, 1, 1);
    const Eigen::Vector3d expected = (im.sform * v) * 1e-3;
    EXPECT_LT((map.affine.topRows<3>() * v - expected).norm(), 1e-7);
    EXPECT_NEAR(map.spacing_m()[0], 1.5e-3, 1e-9);
    EXPECT_NEAR(map.spacing_m()[2], 3e-3, 1e-9);
    EXPECT_NEAR(map.voxel_volume_m3(), 9e-9, 1e-15);
    EXPECT_EQ(map.counts().at(0), 1);
  }
}

TEST(LabelMap, EachFaultOfTheFileIsOneLineNamingTheFileAndTheField) {
  const NiftiImage good = small_image();
  // Not NIfTI at all.
  test::write_bytes(tmp("text.nii"), std::vector<std::uint8_t>(400, 'x'));
  EXPECT_NE(error_of(tmp("text.nii")).find("text.nii: header: is not a NIfTI"), std::string::npos) << error_of(tmp("text.nii"));
  // Truncated: the last 30 voxels missing.
  auto bytes = test::nifti_bytes(good);
  bytes.resize(bytes.size() - 30);
  test::write_bytes(tmp("truncated.nii"), bytes);
  EXPECT_NE(error_of(tmp("truncated.nii")).find("truncated.nii: voxel data: could not read the 120 bytes"), std::string::npos)
      << error_of(tmp("truncated.nii"));
  // A header claiming more voxels than the file holds.
  NiftiImage more = good;
  more.nz = 40;
  bytes = test::nifti_bytes(more);
  bytes.resize(352 + good.labels.size());
  test::write_bytes(tmp("claims-more.nii"), bytes);
  EXPECT_NE(error_of(tmp("claims-more.nii")).find("voxel data: could not read the 1200 bytes"), std::string::npos)
      << error_of(tmp("claims-more.nii"));
  // A gzip stream damaged after its header.
  test::write_nifti(tmp("damaged.nii.gz"), good);
  auto gz = viscera::common::read_file_bytes(tmp("damaged.nii.gz"));
  for (std::size_t k = gz.size() / 2; k < gz.size() - 8; ++k) gz[k] ^= 0x5a;
  test::write_bytes(tmp("damaged-raw.nii.gz.bin"), gz);
  std::filesystem::rename(tmp("damaged-raw.nii.gz.bin"), tmp("damaged.nii.gz"));
  const std::string damaged = error_of(tmp("damaged.nii.gz"));
  EXPECT_NE(damaged.find("damaged.nii.gz: "), std::string::npos) << damaged;
  EXPECT_TRUE(damaged.find("gzip stream is damaged") != std::string::npos || damaged.find("header") != std::string::npos) << damaged;
  // One voxel thick.
  NiftiImage thin = good;
  thin.nz = 1;
  thin.labels.resize(30);
  test::write_nifti(tmp("thin.nii"), thin);
  EXPECT_NE(error_of(tmp("thin.nii")).find("thin.nii: dim[3]: 1 voxel: the image is one voxel thick"), std::string::npos)
      << error_of(tmp("thin.nii"));
  // A singular affine: two columns the same.
  NiftiImage singular = good;
  singular.sform.col(1) = singular.sform.col(0);
  test::write_nifti(tmp("singular.nii"), singular);
  EXPECT_NE(error_of(tmp("singular.nii")).find("singular.nii: srow_x: the voxel-to-patient affine is singular"), std::string::npos)
      << error_of(tmp("singular.nii"));
  // Scaled values are not labels.
  NiftiImage scaled = good;
  scaled.scl_slope = 2.5f;
  test::write_nifti(tmp("scaled.nii"), scaled);
  EXPECT_NE(error_of(tmp("scaled.nii")).find("scaled.nii: scl_slope: 2.5"), std::string::npos) << error_of(tmp("scaled.nii"));
  EXPECT_NE(error_of(tmp("missing.nii")).find("missing.nii: no such file"), std::string::npos);
}

TEST(LabelMap, DescribesThePresentLabelsMostVoxelsFirst) {
  NiftiImage im = small_image();
  std::fill(im.labels.begin(), im.labels.end(), 0);
  for (int k = 0; k < 7; ++k) im.labels[static_cast<std::size_t>(k)] = 5;
  for (int k = 7; k < 10; ++k) im.labels[static_cast<std::size_t>(k)] = 4;
  test::write_nifti(tmp("two.nii"), im);
  EXPECT_EQ(describe_labels(read_label_map(tmp("two.nii"))), "5 (7 voxels), 4 (3 voxels)");
}
