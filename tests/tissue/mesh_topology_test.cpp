// Boundary extraction and 1:8 refinement, checked against topology and geometry identities.  // SPDX-License-Identifier: Apache-2.0
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/refinement.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

// Volume enclosed by the surface (divergence theorem): sum over triangles of x . n A / 3.
double enclosed_volume(const TetMesh& m, const BoundarySurface& s) {
  double v = 0.0;
  for (const auto& t : s.triangles) v += m.nodes[t[0]].dot(m.nodes[t[1]].cross(m.nodes[t[2]])) / 6.0;
  return v;
}

int euler_characteristic(const BoundarySurface& s) {
  std::set<std::pair<int, int>> edges;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) edges.emplace(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
  return static_cast<int>(s.nodes.size()) - static_cast<int>(edges.size()) + static_cast<int>(s.triangles.size());
}

}  // namespace

TEST(BoundarySurface, OrganSurfacesAreClosedOutwardAndEncloseTheMeshVolume) {
  struct Case {
    const char* file;
    std::size_t triangles;  // -1: not documented
    int euler;
  } cases[] = {{"meshes/liver.msh", 276, 2}, {"meshes/liver2.msh", 860, 2}, {"meshes/heart_imstk-unity.vtk", 0, -2}};
  for (const auto& c : cases) {
    const TetMesh m = read_tet_mesh(test::data_path(c.file));
    const BoundarySurface s = extract_boundary(m);
    if (c.triangles) {
      EXPECT_EQ(s.triangles.size(), c.triangles) << c.file;
    }
    EXPECT_EQ(euler_characteristic(s), c.euler) << c.file;  // closed, genus 0 (liver) or 2 (heart)
    EXPECT_NEAR(enclosed_volume(m, s) / mesh_volume(m), 1.0, 1e-12) << c.file;
    for (std::size_t k = 0; k < s.triangles.size(); ++k) {
      const auto& t = s.triangles[k];
      const Tet& owner = m.tets[s.owner_tet[k]];
      const Vec3 n = (m.nodes[t[1]] - m.nodes[t[0]]).cross(m.nodes[t[2]] - m.nodes[t[0]]);
      const Vec3 tc = (m.nodes[owner[0]] + m.nodes[owner[1]] + m.nodes[owner[2]] + m.nodes[owner[3]]) / 4.0;
      const Vec3 fc = (m.nodes[t[0]] + m.nodes[t[1]] + m.nodes[t[2]]) / 3.0;
      ASSERT_GT(n.dot(fc - tc), 0.0) << c.file << " triangle " << k << " points inward";
    }
  }
}

TEST(Refinement, LiverAtThreeLevelsKeepsVolumeSurfaceAndValidity) {
  const TetMesh l0 = read_tet_mesh(test::data_path("meshes/liver2.msh"));
  const TetMesh l1 = refine_uniform(l0);
  const TetMesh l2 = refine_uniform(l1);
  EXPECT_EQ(l1.tet_count(), 8 * 1493u);
  EXPECT_EQ(l2.tet_count(), 64 * 1493u);
  EXPECT_NO_THROW(validate_mesh(l1));
  EXPECT_NO_THROW(validate_mesh(l2));
  EXPECT_NEAR(mesh_volume(l2) / mesh_volume(l0), 1.0, 1e-12);
  const auto s0 = extract_boundary(l0), s2 = extract_boundary(l2);
  EXPECT_EQ(s2.triangles.size(), 16 * s0.triangles.size());
  EXPECT_EQ(euler_characteristic(s2), 2);
  // Quality stays bounded: the shortest-diagonal split loses at most a fixed factor.
  const auto min_quality = [](const TetMesh& m) {
    double q = 1.0;
    for (const auto& t : m.tets) q = std::min(q, tet_quality(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]));
    return q;
  };
  EXPECT_GT(min_quality(l2), 0.25 * min_quality(l0));
}

TEST(BoxMesh, IsConformingAndFillsTheBox) {
  const TetMesh m = make_box_mesh(Vec3(0, 0, 0), Vec3(0.1, 0.02, 0.03), 5, 2, 3);
  EXPECT_EQ(m.tet_count(), 6u * 5 * 2 * 3);
  EXPECT_NO_THROW(validate_mesh(m));
  EXPECT_NEAR(mesh_volume(m), 0.1 * 0.02 * 0.03, 1e-15);
  const auto s = extract_boundary(m);
  EXPECT_EQ(s.triangles.size(), 4u * (5 * 2 + 2 * 3 + 5 * 3));  // conforming: no interior faces left
}

// Element sets survive refinement: each tetrahedron's eight children keep its sets, fill exactly
// its volume and lie inside it (their centroids, by barycentric coordinates in the parent).
TEST(Refinement, ChildrenKeepTheirParentsElementSets) {
  TetMesh l0 = make_box_mesh(Vec3(0, 0, 0), Vec3(0.03, 0.02, 0.01), 3, 2, 1);
  l0.element_sets = {{4, "end", {}}, {9, "", {0, 5}}};
  for (std::int32_t e = 0; e < static_cast<std::int32_t>(l0.tet_count()); ++e)
    if (e % 3 == 1) l0.element_sets[0].tets.push_back(e);
  const TetMesh l2 = refine_uniform(refine_uniform(l0));
  ASSERT_EQ(l2.element_sets.size(), 2u);
  const auto volume = [](const TetMesh& m, const std::vector<std::int32_t>& tets) {
    double v = 0;
    for (const auto e : tets) v += signed_volume(m.nodes[m.tets[e][0]], m.nodes[m.tets[e][1]], m.nodes[m.tets[e][2]], m.nodes[m.tets[e][3]]);
    return v;
  };
  for (std::size_t k = 0; k < 2; ++k) {
    const ElementSet &parent = l0.element_sets[k], &child = l2.element_sets[k];
    EXPECT_EQ(child.tag, parent.tag);
    EXPECT_EQ(child.name, parent.name);
    ASSERT_EQ(child.tets.size(), 64 * parent.tets.size());
    EXPECT_NEAR(volume(l2, child.tets), volume(l0, parent.tets), 1e-15);
    for (const auto c : child.tets) {
      const auto& ct = l2.tets[c];
      const Vec3 centroid = 0.25 * (l2.nodes[ct[0]] + l2.nodes[ct[1]] + l2.nodes[ct[2]] + l2.nodes[ct[3]]);
      const auto& pt = l0.tets[c / 64];
      Eigen::Matrix3d M;
      M << l0.nodes[pt[1]] - l0.nodes[pt[0]], l0.nodes[pt[2]] - l0.nodes[pt[0]], l0.nodes[pt[3]] - l0.nodes[pt[0]];
      const Vec3 w = M.partialPivLu().solve(centroid - l0.nodes[pt[0]]);
      EXPECT_TRUE(w.minCoeff() > 0 && w.sum() < 1) << "child " << c << " lies outside its parent " << c / 64;
    }
  }
}

TEST(MeshValidation, AFaceSharedByThreeTetrahedraIsCountedOnce) {
  // Three tetrahedra on one triangle (apexes above, below and beside it): one face too many;
  // a box mesh and its refinement: none.
  TetMesh m = make_box_mesh(Vec3(0, 0, 0), Vec3(0.03, 0.02, 0.02), 3, 2, 2);
  EXPECT_EQ(overshared_faces(m), 0u);
  EXPECT_EQ(overshared_faces(refine_uniform(m)), 0u);
  TetMesh fan;
  fan.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, -1), Vec3(0.3, 0.3, 0.5)};
  fan.tets = {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 1, 2, 5}};
  EXPECT_EQ(overshared_faces(fan), 1u);
  fan.tets.push_back({0, 1, 2, 3});  // and a fourth on the same face is still one face
  EXPECT_EQ(overshared_faces(fan), 1u);
}
