// viscera-mesh as a user runs it, on label maps the test writes (an ellipsoid organ with a  // SPDX-License-Identifier: Apache-2.0
// spherical nodule: volumes and surfaces known in closed form) and on the bundled patient's map
// (volumes counted, the label boundary measured by the test from the voxels). The mesh is read back
// with viscera's own Gmsh reader, which validates it (no inverted, degenerate or repeated element).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/percentile.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"

#include "nifti_file.hpp"
#include "tet_quality.hpp"

using namespace viscera;
using Eigen::Vector3d;
using meshing::test::NiftiImage;

namespace {

const std::string kProgram = VISCERA_MESH_PROGRAM;
const std::string kData = VISCERA_DATA_DIR;

std::string tmp(const std::string& name) {
  std::filesystem::create_directories(VISCERA_TEST_TMP);
  return std::string(VISCERA_TEST_TMP) + "/" + name;
}

struct Outcome {
  int status = -1;
  std::string output;  ///< stdout and stderr
};

Outcome run(const std::string& args) {
  const std::string log = tmp("run.log");
  const int raw = std::system((kProgram + " " + args + " > " + log + " 2>&1").c_str());
  std::ifstream in(log);
  std::stringstream s;
  s << in.rdbuf();
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, s.str()};
}

double signed_volume(const tissue::TetMesh& m, const tissue::Tet& t) {
  const Vector3d& a = m.nodes[t[0]];
  return (m.nodes[t[1]] - a).dot((m.nodes[t[2]] - a).cross(m.nodes[t[3]] - a)) / 6;
}

/// The label of each tetrahedron from the mesh's element sets (named groups; "held" is not a label).
std::vector<std::string> labels_of(const tissue::TetMesh& m) {
  std::vector<std::string> label(m.tet_count());
  for (const auto& set : m.element_sets)
    if (set.name != "held")
      for (const std::int32_t e : set.tets) label[static_cast<std::size_t>(e)] = set.name;
  return label;
}

/// Faces by sorted vertices: the tetrahedra on each side.
std::map<std::array<std::int32_t, 3>, std::vector<std::int32_t>> face_sides(const tissue::TetMesh& m) {
  std::map<std::array<std::int32_t, 3>, std::vector<std::int32_t>> sides;
  for (std::size_t e = 0; e < m.tet_count(); ++e)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<std::int32_t, 3> f{};
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (k != skip) f[static_cast<std::size_t>(n++)] = m.tets[e][static_cast<std::size_t>(k)];
      std::sort(f.begin(), f.end());
      sides[f].push_back(static_cast<std::int32_t>(e));
    }
  return sides;
}

// The phantom: an ellipsoid (semi-axes 45, 35, 28 mm) with a spherical nodule (radius 13 mm) inside,
// on voxels of 1.5 x 2 x 2.5 mm, turned by the sform (30 degrees about z, then 10 about x) and moved.
constexpr double kA = 45, kB = 35, kC = 28, kR = 13;
const Vector3d kNodule(12, 6, 3);
const Vector3d kSpacing(1.5, 2.0, 2.5);

struct Phantom {
  NiftiImage image;
  Eigen::Matrix3d rotation;
  Vector3d centre_mm;  ///< the ellipsoid's centre in index-scaled millimetres
};

Phantom make_phantom() {
  Phantom p;
  NiftiImage& im = p.image;
  im.nx = 70, im.ny = 42, im.nz = 30;
  p.centre_mm = Vector3d(im.nx - 1, im.ny - 1, im.nz - 1).cwiseProduct(kSpacing) / 2;
  for (int k = 0; k < im.nz; ++k)
    for (int j = 0; j < im.ny; ++j)
      for (int i = 0; i < im.nx; ++i) {
        const Vector3d x = Vector3d(i, j, k).cwiseProduct(kSpacing) - p.centre_mm;
        std::uint8_t l = 0;
        if ((x - kNodule).norm() <= kR)
          l = 2;
        else if (std::pow(x.x() / kA, 2) + std::pow(x.y() / kB, 2) + std::pow(x.z() / kC, 2) <= 1)
          l = 1;
        im.labels.push_back(l);
      }
  p.rotation = (Eigen::AngleAxisd(10 * std::numbers::pi / 180, Vector3d::UnitX()) * Eigen::AngleAxisd(std::numbers::pi / 6, Vector3d::UnitZ()))
                   .toRotationMatrix();
  im.sform.leftCols<3>() = p.rotation * kSpacing.asDiagonal();
  im.sform.col(3) = Vector3d(-80, 40, 120);
  return p;
}

}  // namespace

TEST(VisceraMesh, APhantomsLabelsAreMeshedToTheirAnalyticVolumesAndSurfacesWithWellShapedElements) {
  const Phantom p = make_phantom();
  meshing::test::write_nifti(tmp("phantom.nii.gz"), p.image);
  const std::string out = tmp("phantom-out");
  const Outcome r = run(tmp("phantom.nii.gz") + " --organ 1 --organ-name body --region 2:nodule:" + kData + "/materials/nodule.json --material " +
                        kData + "/materials/liver.json --tets 20000 --frame patient --out " + out + " --name phantom --replace");
  ASSERT_EQ(r.status, 0) << r.output;
  const tissue::TetMesh mesh = tissue::read_tet_mesh(out + "/phantom.msh");  // validated: nothing inverted, degenerate or repeated
  const auto label = labels_of(mesh);
  // Patient metres -> the phantom's own frame in millimetres (its analytic shapes).
  const auto local = [&](const Vector3d& x) { return Vector3d(p.rotation.transpose() * (x * 1e3 - p.image.sform.col(3)) - p.centre_mm); };
  double body = 0, nodule = 0;
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) (label[e] == "nodule" ? nodule : body) += signed_volume(mesh, mesh.tets[e]) * 1e9;
  const double sphere = 4.0 / 3 * std::numbers::pi * kR * kR * kR;
  const double ellipsoid = 4.0 / 3 * std::numbers::pi * kA * kB * kC;
  EXPECT_NEAR(nodule / sphere, 1, 0.02) << nodule << " mm^3 meshed for a sphere of " << sphere;
  EXPECT_NEAR(body / (ellipsoid - sphere), 1, 0.02) << body << " mm^3 meshed for " << ellipsoid - sphere;
  // Surfaces: the outer boundary against the ellipsoid, the nodule's against its sphere, at their
  // nodes; first-order distance to the ellipsoid |f - 1| / |grad f| (its error is second order).
  std::vector<double> outer, inner;
  for (const auto& [face, tets] : face_sides(mesh)) {
    const bool on_outside = tets.size() == 1;
    const bool on_nodule =
        tets.size() == 2 && (label[static_cast<std::size_t>(tets[0])] == "nodule") != (label[static_cast<std::size_t>(tets[1])] == "nodule");
    for (const std::int32_t v : face) {
      const Vector3d x = local(mesh.nodes[static_cast<std::size_t>(v)]);
      if (on_outside) {
        const Vector3d q(x.x() / (kA * kA), x.y() / (kB * kB), x.z() / (kC * kC));
        const double f = x.x() * q.x() + x.y() * q.y() + x.z() * q.z();
        outer.push_back(std::abs(f - 1) / (2 * q.norm()));
      }
      if (on_nodule) inner.push_back(std::abs((x - kNodule).norm() - kR));
    }
  }
  const double diagonal = kSpacing.norm();  // 3.54 mm
  ASSERT_GT(outer.size(), 500U);
  ASSERT_GT(inner.size(), 50U);
  EXPECT_LT(common::percentile(outer, 0.95), diagonal);
  EXPECT_LT(common::percentile(inner, 0.95), diagonal);
  // Shapes.
  std::vector<Vector3d> nodes(mesh.nodes.begin(), mesh.nodes.end());
  std::vector<std::array<std::int32_t, 4>> tets(mesh.tets.begin(), mesh.tets.end());
  const meshing::QualitySummary q = meshing::summarize_quality(nodes, tets);
  EXPECT_EQ(q.inverted_or_flat, 0U);
  EXPECT_GE(q.min_dihedral_deg, 5);
  EXPECT_NEAR(static_cast<double>(mesh.tet_count()) / 20000, 1, 0.1);
  // The report gives the distribution and each stage's time.
  std::ifstream in(out + "/reports/phantom.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["quality"]["min_dihedral_histogram_5deg"].size(), 15U);
  EXPECT_GT(report["stages_s"]["mesh_s"].get<double>(), 0);
  EXPECT_GT(report["calibration"]["explicit_step_s"].get<double>(), 0);
  std::printf(
      "phantom: %zu tetrahedra; nodule %.2f%%, body %.2f%% of analytic volume; surface p95 %.2f mm (outer), %.2f mm (nodule); min dihedral %.1f "
      "deg\n",
      mesh.tet_count(), 100 * (nodule / sphere - 1), 100 * (body / (ellipsoid - sphere) - 1), common::percentile(outer, 0.95),
      common::percentile(inner, 0.95), q.min_dihedral_deg);
}

TEST(VisceraMesh, ThePatientsLiverAndGallbladderKeepTheirVoxelVolumesConformAndFollowTheLabelBoundary) {
  const std::string map = kData + "/label-maps/abdomen-totalsegmentator/example_seg.nii.gz";
  const std::string out = tmp("patient-out");
  const Outcome r = run(map + " --organ 5 --organ-name liver --region 4:gallbladder:" + kData + "/materials/gallbladder.json --material " + kData +
                        "/materials/liver-viscoelastic.json --hold-touching 63 --hold-crop --frame patient --tets 12000 --out " + out +
                        " --name liver --replace --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  const NiftiImage im = meshing::test::read_nifti_u8(map);
  const Eigen::Matrix3d s = im.sform.leftCols<3>();
  const double voxel_mm3 = std::abs(s.determinant());
  std::map<int, double> voxels;
  for (const std::uint8_t l : im.labels) voxels[l] += voxel_mm3;
  const tissue::TetMesh mesh = tissue::read_tet_mesh(out + "/liver.msh");
  const auto label = labels_of(mesh);
  std::map<std::string, double> volume;
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) volume[label[e]] += signed_volume(mesh, mesh.tets[e]) * 1e9;
  EXPECT_NEAR(volume["liver"] / voxels[5], 1, 0.03) << volume["liver"] << " mm^3 meshed, " << voxels[5] << " of voxels";
  EXPECT_NEAR(volume["gallbladder"] / voxels[4], 1, 0.05) << volume["gallbladder"] << " mm^3 meshed, " << voxels[4] << " of voxels";
  // Conforming: every face has one or two tetrahedra; liver and gallbladder share faces (their
  // nodes); a face with one tetrahedron lies on the organ's outside: within a voxel diagonal of a
  // voxel of neither label (a gap between the two would leave faces deep inside the labels).
  const Eigen::Matrix3d to_index = s.inverse();
  const Vector3d shift = im.sform.col(3);
  const double diagonal = s.colwise().norm().norm();
  const auto label_at = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= im.nx || j >= im.ny || k >= im.nz) return 0;
    return static_cast<int>(im.labels[(static_cast<std::size_t>(k) * im.ny + j) * im.nx + i]);
  };
  const auto near_outside = [&](const Vector3d& x_mm) {
    const Vector3d q = to_index * (x_mm - shift);
    for (int k = static_cast<int>(q.z()) - 2; k <= static_cast<int>(q.z()) + 3; ++k)
      for (int j = static_cast<int>(q.y()) - 2; j <= static_cast<int>(q.y()) + 3; ++j)
        for (int i = static_cast<int>(q.x()) - 2; i <= static_cast<int>(q.x()) + 3; ++i) {
          const int l = label_at(i, j, k);
          if (l != 4 && l != 5 && (s * (Vector3d(i, j, k) - q)).norm() <= diagonal) return true;
        }
    return false;
  };
  std::size_t shared = 0, outside = 0, inside = 0;
  for (const auto& [face, tets] : face_sides(mesh)) {
    ASSERT_LE(tets.size(), 2U);
    if (tets.size() == 2 && label[static_cast<std::size_t>(tets[0])] != label[static_cast<std::size_t>(tets[1])]) ++shared;
    if (tets.size() == 1) {
      const Vector3d c = (mesh.nodes[face[0]] + mesh.nodes[face[1]] + mesh.nodes[face[2]]) * (1e3 / 3);
      ++(near_outside(c) ? outside : inside);
    }
  }
  EXPECT_GT(shared, 50U);
  EXPECT_EQ(inside, 0U) << "faces with one tetrahedron inside the labels (a gap), of " << outside + inside;
  // The liver's surface (its faces against anything but liver) against the label's voxel boundary,
  // measured here from the voxels: the exact distance to each boundary face of a liver voxel.
  struct Square {
    Vector3d voxel;
    int axis, side;
  };
  std::vector<Square> boundary;
  for (int k = 0; k < im.nz; ++k)
    for (int j = 0; j < im.ny; ++j)
      for (int i = 0; i < im.nx; ++i) {
        if (label_at(i, j, k) != 5) continue;
        for (int a = 0; a < 3; ++a)
          for (int side = -1; side <= 1; side += 2) {
            int n[3] = {i, j, k};
            n[a] += side;
            const bool edge = n[a] < 0 || n[a] >= (a == 0 ? im.nx : a == 1 ? im.ny : im.nz);
            if (edge || label_at(n[0], n[1], n[2]) != 5) boundary.push_back({Vector3d(i, j, k), a, side});
          }
      }
  std::vector<char> measured(mesh.node_count(), 0);
  std::vector<double> distance;
  for (const auto& [face, tets] : face_sides(mesh)) {
    const int livers =
        static_cast<int>(std::count_if(tets.begin(), tets.end(), [&](std::int32_t e) { return label[static_cast<std::size_t>(e)] == "liver"; }));
    if (livers != 1 || tets.size() - 1 > 1) continue;
    if (tets.size() == 2 && livers == 1 && label[static_cast<std::size_t>(tets[0])] == label[static_cast<std::size_t>(tets[1])]) continue;
    for (const std::int32_t v : face) {
      if (measured[static_cast<std::size_t>(v)]) continue;
      measured[static_cast<std::size_t>(v)] = 1;
      const Vector3d q = to_index * (mesh.nodes[static_cast<std::size_t>(v)] * 1e3 - shift);
      double best = 1e300;
      for (const Square& b : boundary) {
        Vector3d c = q.cwiseMax(b.voxel - Vector3d::Constant(0.5)).cwiseMin(b.voxel + Vector3d::Constant(0.5));
        c[b.axis] = b.voxel[b.axis] + 0.5 * b.side;
        best = std::min(best, (s * (c - q)).norm());
      }
      distance.push_back(best);
    }
  }
  ASSERT_GT(distance.size(), 500U);
  EXPECT_LT(common::percentile(distance, 0.95), diagonal);
  std::ifstream in(out + "/reports/liver.json");
  const auto report = nlohmann::json::parse(in);
  if (VISCERA_TIMED) {
    EXPECT_LT(report["stages_s"]["total_s"].get<double>(), 60);
  }
  EXPECT_GT(report["held"]["faces"].get<int>(), 0);
  std::printf(
      "patient: %zu tetrahedra; liver %+.2f%%, gallbladder %+.2f%% of their voxels; %zu shared faces; liver surface p95 %.2f mm (diagonal %.2f); "
      "%.1f s\n",
      mesh.tet_count(), 100 * (volume["liver"] / voxels[5] - 1), 100 * (volume["gallbladder"] / voxels[4] - 1), shared,
      common::percentile(distance, 0.95), diagonal, report["stages_s"]["total_s"].get<double>());
}

TEST(VisceraMesh, BadInputIsOneLineNamingTheFileAndTheLabelAndNothingIsWrittenOver) {
  NiftiImage im;
  im.nx = 20, im.ny = 20, im.nz = 20;
  im.labels.assign(8000, 0);
  for (int k = 5; k < 15; ++k)
    for (int j = 5; j < 15; ++j)
      for (int i = 5; i < 15; ++i) im.labels[(static_cast<std::size_t>(k) * 20 + j) * 20 + i] = 3;
  for (int i = 0; i < 5; ++i) im.labels[static_cast<std::size_t>(i)] = 7;  // a label of 5 voxels
  im.sform.leftCols<3>() = Eigen::Matrix3d::Identity() * 2;
  const std::string map = tmp("cube.nii");
  meshing::test::write_nifti(map, im);
  const std::string materials = " --material " + kData + "/materials/liver.json";
  const std::string out = tmp("bad-out");
  std::filesystem::remove_all(out);
  const auto one_line = [](const Outcome& r, const std::string& expected) {
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
  };
  one_line(run(map + " --organ 9" + materials + " --out " + out), map + ": label 9: is not in the image; its labels: 3 (1000 voxels), 7 (5 voxels)");
  one_line(run(map + " --organ 3 --region 7:speck:" + kData + "/materials/nodule.json" + materials + " --out " + out),
           map + ": label 7: has 5 voxels, fewer than 27");
  one_line(run(map + " --organ 3 --tets 50" + materials + " --out " + out), "--tets");
  one_line(run(map + " --organ 3 --hold-touching 3" + materials + " --out " + out), "label 3: is part of the organ");
  one_line(run(tmp("absent.nii") + " --organ 3" + materials + " --out " + out), "absent.nii: no such file");
  meshing::test::write_bytes(tmp("words.nii"), std::vector<std::uint8_t>(500, 'a'));
  one_line(run(tmp("words.nii") + " --organ 3" + materials + " --out " + out), "words.nii: header: is not a NIfTI");
  // A first run writes; a second is refused without --replace and leaves the files as they were.
  const Outcome first = run(map + " --organ 3 --tets 2000" + materials + " --out " + out + " --name cube --quiet");
  ASSERT_EQ(first.status, 0) << first.output;
  const auto before = std::filesystem::last_write_time(out + "/cube.msh");
  one_line(run(map + " --organ 3 --tets 2000" + materials + " --out " + out + " --name cube"), out + "/cube.msh: ");
  EXPECT_EQ(std::filesystem::last_write_time(out + "/cube.msh"), before);
  // Never through a link: with --replace, a link planted at an output is refused, its target untouched.
  const std::string target = tmp("precious.txt");
  meshing::test::write_bytes(target, {'k', 'e', 'e', 'p'});
  std::filesystem::remove(out + "/cube.svg");
  std::filesystem::create_symlink(target, out + "/cube.svg");
  const Outcome linked = run(map + " --organ 3 --tets 2000" + materials + " --out " + out + " --name cube --replace --quiet");
  EXPECT_EQ(linked.status, 2) << linked.output;
  EXPECT_NE(linked.output.find("cube.svg"), std::string::npos) << linked.output;
  EXPECT_EQ(viscera::common::read_file_bytes(target).size(), 4U);
  // An output is never an input, even with --replace: the scene NAME.json would be the material.
  std::filesystem::create_directories(tmp("same"));
  std::filesystem::copy_file(kData + "/materials/liver.json", tmp("same/m.json"), std::filesystem::copy_options::overwrite_existing);
  one_line(run(map + " --organ 3 --material " + tmp("same/m.json") + " --out " + tmp("same") + " --name m --replace"), tmp("same/m.json"));
}
