// Material regions: laid out on the mesh as stated, calibrated per element (a two-material bar in  // SPDX-License-Identifier: Apache-2.0
// series against its closed form; a region over the whole organ against the organ made of the
// region's material), drawn centres that keep their promises (checked by point location in the
// mesh, not by the code that drew them), and scene-file errors that name the field.
#include "viscera/runtime/material_regions.hpp"

#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include <Eigen/SparseCholesky>
#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"

using namespace viscera::runtime;
using namespace viscera::tissue;
using viscera::common::InputError;

namespace {

/// These tests are about materials, not this machine's speed: the tick may take any time (a
/// sanitized build on a loaded CI machine takes 5.6 ms per sub-step of the stiff liver).
const TickBudget kUntimed{1e9};

std::string data(const std::string& rel) { return std::string(VISCERA_DATA_DIR) + "/" + rel; }

std::string write(const std::string& name, const std::string& text) {
  const std::string dir = std::string(VISCERA_TEST_TMP) + "/regions";
  std::filesystem::create_directories(dir);
  std::string p = dir + "/" + name;
  std::ofstream(p) << text;
  return p;
}

RegionSpec box_region(const std::string& name, const Vec3& lo, const Vec3& hi) {
  RegionSpec r;
  r.name = name;
  r.shape = RegionSpec::Shape::box;
  r.lo_m = {lo.x(), lo.y(), lo.z()};
  r.hi_m = {hi.x(), hi.y(), hi.z()};
  return r;
}

/// Whether p lies in some tetrahedron of the mesh (barycentric coordinates, a small tolerance).
bool inside(const TetMesh& mesh, const Vec3& p) {
  for (const auto& t : mesh.tets) {
    const Vec3 &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]], &d = mesh.nodes[t[3]];
    Eigen::Matrix3d M;
    M << b - a, c - a, d - a;
    const Vec3 w = M.partialPivLu().solve(p - a);
    if (w.minCoeff() >= -1e-9 && w.sum() <= 1 + 1e-9) return true;
  }
  return false;
}

/// A scene for the bundled liver with the given regions (JSON text of the "regions" array).
std::string liver_scene(const std::string& name, const std::string& material, const std::string& regions) {
  return write(name + ".json",
               R"({"name": ")" + name + R"(", "organ": {"mesh": ")" + data("meshes/liver2.msh") + R"(", "scale_m_per_unit": 0.08, "material": ")" +
                   material + R"(", "volume_term": 0.5, "fix_slab": ["z", "min", 0.2], "regions": )" + regions + R"(}, "instruments": [{"id": 1}]})");
}

std::string isotropic(const std::string& name, double E, double density, const std::string& viscoelasticity = "") {
  return write(name + ".json", R"({"name": ")" + name + R"(", "density_kg_m3": )" + std::to_string(density) +
                                   R"(, "elasticity": {"type": "isotropic", "youngs_modulus_pa": )" + std::to_string(E) +
                                   R"(, "poisson_ratio": 0.45})" + (viscoelasticity.empty() ? "" : ", \"viscoelasticity\": " + viscoelasticity) +
                                   "}");
}

}  // namespace

// Two materials in series along a bar (Poisson's ratio 0, so the uniaxial stress is the exact
// linear solution): the end moves by sigma (L1 / E1 + L2 / E2). The GPS equals linear FE at small
// strain element by element, so its tangent at rest must give that to rounding.
TEST(MaterialRegions, ABarOfTwoMaterialsInSeriesStretchesAsTheClosedForm) {
  const double L = 0.1, W = 0.02, E1 = 4e3, E2 = 30e3, sigma = 50.0;
  const auto mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(L, W, W), 10, 2, 2));
  const BoundarySurface boundary = extract_boundary(*mesh);
  // The far 30% of the bar (a plane of nodes at x = 0.07) is the second material.
  const RegionLayout layout =
      lay_out_regions({box_region("end", Vec3(0.07, -1, -1), Vec3(1, 1, 1))}, *mesh, boundary, Box{Vec3::Constant(-9), Vec3::Constant(-8)}, "bar");
  ASSERT_EQ(layout.regions.size(), 1u);
  EXPECT_EQ(layout.regions[0].elements, mesh->tet_count() * 3 / 10);
  EXPECT_NEAR(layout.regions[0].volume_m3, 0.03 * W * W, 1e-15);
  for (const double volume_term : {0.0, 0.5}) {
    GpsOptions options;
    options.variant = GpsVariant::energy_consistent;
    options.volume_stiffness_fraction = volume_term;
    const GpsModel model(mesh, {elasticity_matrix(IsotropicElasticity{E1, 0.0}), elasticity_matrix(IsotropicElasticity{E2, 0.0})},
                         layout.material_of_tet, options);
    const std::size_t n = mesh->node_count();
    std::vector<Eigen::Triplet<double>> k;
    for (std::size_t e = 0; e < mesh->tet_count(); ++e) {
      const Mat12 Ke = model.element_tangent(mesh->nodes, e);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) k.emplace_back(3 * mesh->tets[e][a] + i, 3 * mesh->tets[e][b] + j, Ke(3 * a + i, 3 * b + j));
    }
    Eigen::SparseMatrix<double> K(3 * n, 3 * n);
    K.setFromTriplets(k.begin(), k.end());
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * n);
    for (const auto& t : boundary.triangles) {  // the traction on the end face, as consistent nodal forces
      const Vec3 &a = mesh->nodes[t[0]], &b = mesh->nodes[t[1]], &c = mesh->nodes[t[2]];
      if (a.x() > L - 1e-12 && b.x() > L - 1e-12 && c.x() > L - 1e-12)
        for (const auto v : t) f(3 * v) += sigma * 0.5 * (b - a).cross(c - a).norm() / 3.0;
    }
    // The face x = 0 held: a penalty far stiffer than the bar on its nodes' three directions.
    for (std::size_t v = 0; v < n; ++v)
      if (mesh->nodes[v].x() < 1e-12)
        for (int i = 0; i < 3; ++i) K.coeffRef(3 * v + i, 3 * v + i) += 1e15;
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(K);
    ASSERT_EQ(solver.info(), Eigen::Success);
    const Eigen::VectorXd u = solver.solve(f);
    const double expected = sigma * (0.07 / E1 + 0.03 / E2);
    for (std::size_t v = 0; v < n; ++v) {
      const Vec3& X = mesh->nodes[v];
      const double exact = X.x() <= 0.07 ? sigma * X.x() / E1 : sigma * (0.07 / E1 + (X.x() - 0.07) / E2);
      EXPECT_NEAR(u(3 * v), exact, 1e-9 * expected) << "node " << v << " at x = " << X.x() << ", volume term " << volume_term;
      EXPECT_NEAR(u(3 * v + 1), 0.0, 1e-9 * expected);
      EXPECT_NEAR(u(3 * v + 2), 0.0, 1e-9 * expected);
    }
  }
}

namespace {

/// The mesh as a Gmsh 4.1 file whose tetrahedra with their centroid beyond x = x_split are volume
/// entity 2, in the physical group 7 named "far end"; the others entity 1, group 3 (unnamed).
std::string gmsh_with_groups(const TetMesh& mesh, double x_split) {
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 7 \"far end\"\n$EndPhysicalNames\n";
  s += "$Entities\n0 0 0 2\n1 0 0 0 1 1 1 1 3 0\n2 0 0 0 1 1 1 1 7 0\n$EndEntities\n";
  const std::size_t n = mesh.node_count();
  s += "$Nodes\n1 " + std::to_string(n) + " 1 " + std::to_string(n) + "\n3 1 0 " + std::to_string(n) + "\n";
  for (std::size_t i = 0; i < n; ++i) s += std::to_string(i + 1) + "\n";
  char b[200];
  for (const Vec3& p : mesh.nodes) {
    std::snprintf(b, sizeof b, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    s += b;
  }
  std::vector<std::size_t> block[2];
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto& t = mesh.tets[e];
    block[(mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]] + mesh.nodes[t[3]]).x() / 4 > x_split ? 1 : 0].push_back(e);
  }
  s += "$EndNodes\n$Elements\n2 " + std::to_string(mesh.tet_count()) + " 1 " + std::to_string(mesh.tet_count()) + "\n";
  for (int k = 0; k < 2; ++k) {
    s += "3 " + std::to_string(k + 1) + " 4 " + std::to_string(block[k].size()) + "\n";
    for (const std::size_t e : block[k]) {
      s += std::to_string(e + 1);
      for (const auto v : mesh.tets[e]) s += " " + std::to_string(v + 1);
      s += "\n";
    }
  }
  return s + "$EndElements\n";
}

}  // namespace

// A tagged element set as a region: the same elements as the box that holds them (another code
// path: centroids in a box), described by their exact centroid and bounding box; kept through the
// scene's refinement (8 children each, the same volume); an unknown set names the field and the
// groups the mesh has.
TEST(MaterialRegions, ATaggedElementSetIsTheRegionOfTheElementsTheFileTagged) {
  const TetMesh box = make_box_mesh(Vec3(0, 0, 0), Vec3(0.1, 0.02, 0.02), 10, 2, 2);
  const std::string mesh_file = write("bar-groups.msh", gmsh_with_groups(box, 0.07));
  const auto mesh = std::make_shared<TetMesh>(read_tet_mesh(mesh_file));
  const BoundarySurface boundary = extract_boundary(*mesh);
  const Box nowhere{Vec3::Constant(-9), Vec3::Constant(-8)};
  const RegionLayout by_box = lay_out_regions({box_region("end", Vec3(0.07, -1, -1), Vec3(1, 1, 1))}, *mesh, boundary, nowhere, "bar");
  for (const std::string set : {"far end", "7"}) {
    RegionSpec tagged;
    tagged.name = "end";
    tagged.shape = RegionSpec::Shape::elements;
    tagged.element_set = set;
    const RegionLayout by_tag = lay_out_regions({tagged}, *mesh, boundary, nowhere, "bar");
    EXPECT_EQ(by_tag.material_of_tet, by_box.material_of_tet) << set;
    ASSERT_EQ(by_tag.regions.size(), 1u);
    EXPECT_EQ(by_tag.regions[0].elements, mesh->tet_count() * 3 / 10);
    EXPECT_NEAR(by_tag.regions[0].volume_m3, 0.03 * 0.02 * 0.02, 1e-15);
    EXPECT_LT((by_tag.regions[0].center_m - Vec3(0.085, 0.01, 0.01)).norm(), 1e-12);
    EXPECT_LT((by_tag.regions[0].box.lo - Vec3(0.07, 0, 0)).norm(), 1e-12);
    EXPECT_LT((by_tag.regions[0].box.hi - Vec3(0.1, 0.02, 0.02)).norm(), 1e-12);
  }
  // Through a scene, refined once: the region holds the children of the tagged elements.
  const std::string stiff = isotropic("stiff-tag", 40e3, 1100), soft = isotropic("soft-tag", 5e3, 1060);
  const auto scene = [&](const std::string& name, const std::string& set) {
    return write(name + ".json", R"({"name": ")" + name + R"(", "organ": {"mesh": ")" + mesh_file + R"(", "material": ")" + soft +
                                     R"(", "refine": 1, "fix_slab": ["x", "min", 0.1], "regions": [{"name": "end", "material": ")" + stiff +
                                     R"(", "elements": )" + set + "}]}, \"instruments\": [{\"id\": 1}]}");
  };
  const auto organ = build_organ(read_scene_file(scene("tagged", R"("far end")")), kUntimed);
  ASSERT_EQ(organ->regions.regions.size(), 1u);
  EXPECT_EQ(organ->regions.regions[0].elements, 8 * mesh->tet_count() * 3 / 10);
  EXPECT_NEAR(organ->regions.regions[0].volume_m3, 0.03 * 0.02 * 0.02, 1e-15);
  const auto info = organ->region_info();
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].shape, viscera::protocol::RegionShape::elements);
  EXPECT_NEAR(info[0].center[0], 0.085, 1e-12);
  const auto error = [&](const std::string& name, const std::string& set) {
    try {
      build_organ(read_scene_file(scene(name, set)), kUntimed);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("untagged", R"("tumour")")
                .find("organ.regions[0].elements: 'tumour' is not a physical group of the organ's mesh (its volume groups: 3, 7 'far end')"),
            std::string::npos)
      << error("untagged", R"("tumour")");
  EXPECT_NE(error("zero", "0").find("organ.regions[0].elements: '0' is neither the name"), std::string::npos) << error("zero", "0");
  EXPECT_NE(error("list", "[7]").find("organ.regions[0].elements"), std::string::npos);
}

// An organ held by an element set (fix_elements, as viscera-mesh writes for a patient's organ):
// the nodes of its tetrahedra's boundary faces are fixed, the same nodes as the slab that holds
// those tetrahedra (another code path: boundary nodes in a box), through the scene's refinement.
TEST(MaterialRegions, AnOrganHeldByAnElementSetFixesTheBoundaryNodesOfItsTetrahedra) {
  const TetMesh box = make_box_mesh(Vec3(0, 0, 0), Vec3(0.1, 0.02, 0.02), 10, 2, 2);
  const std::string mesh_file = write("held-groups.msh", gmsh_with_groups(box, 0.07));
  const std::string soft = isotropic("soft-held", 5e3, 1060);
  const auto scene = [&](const std::string& name, const std::string& holding) {
    return write(name + ".json", R"({"name": ")" + name + R"(", "organ": {"mesh": ")" + mesh_file + R"(", "material": ")" + soft +
                                     R"(", "refine": 1, )" + holding + "}, \"instruments\": [{\"id\": 1}]}");
  };
  const auto held = build_organ(read_scene_file(scene("held-set", R"("fix_elements": "far end")")), kUntimed);
  const auto slab = build_organ(read_scene_file(scene("held-slab", R"("fix_slab": ["x", "max", 0.3])")), kUntimed);
  auto fixed = held->integrator->boundary_conditions().fixed_nodes, expected = slab->integrator->boundary_conditions().fixed_nodes;
  std::sort(fixed.begin(), fixed.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(fixed, expected);
  EXPECT_GT(fixed.size(), 20u);
  const auto error = [&](const std::string& name, const std::string& holding) {
    try {
      build_organ(read_scene_file(scene(name, holding)), kUntimed);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("held-unknown", R"("fix_elements": "liver")")
                .find("organ.fix_elements: 'liver' is not a physical group of the organ's mesh (its volume groups: 3, 7 'far end')"),
            std::string::npos)
      << error("held-unknown", R"("fix_elements": "liver")");
  EXPECT_NE(error("held-both", R"("fix_elements": 7, "fix_slab": ["x", "max", 0.3])").find("organ.fix_elements: the organ is held either by a slab"),
            std::string::npos);
  EXPECT_NE(error("held-zero", R"("fix_elements": 0)").find("organ.fix_elements: '0' is neither the name"), std::string::npos);
}

// A region over the whole organ gives the organ made of the region's material, through the
// server's own building path (the region's unrelaxed elasticity from the organ's relaxation);
// a nodule changes the forces of its own elements only.
TEST(MaterialRegions, ARegionOverTheWholeOrganIsTheOrganMadeOfItsMaterial) {
  const std::string q = R"({"shear_q": 4.8, "bulk_q": 20})";
  const std::string soft = isotropic("soft", 5e3, 1060, q), stiff = isotropic("stiff", 40e3, 1100), stiff_ve = isotropic("stiff-ve", 40e3, 1100, q);
  const auto whole =
      build_organ(read_scene_file(liver_scene(
                      "whole", soft, R"([{"name": "all", "material": ")" + stiff + R"(", "box": {"lo_m": [-9, -9, -9], "hi_m": [9, 9, 9]}}])")),
                  kUntimed);
  const auto plain = build_organ(read_scene_file(liver_scene("plain", stiff_ve, "[]")), kUntimed);
  ASSERT_EQ(whole->regions.regions.at(0).elements, whole->mesh->tet_count());
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 1e-3);
  std::vector<Vec3> x = whole->mesh->nodes;
  for (auto& p : x) p += Vec3(n(rng), n(rng), n(rng));
  std::vector<Vec3> f1(x.size(), Vec3::Zero()), f2(x.size(), Vec3::Zero());
  whole->model->add_forces(x, f1);
  plain->model->add_forces(x, f2);
  double largest = 0;
  for (std::size_t v = 0; v < x.size(); ++v) largest = std::max(largest, f2[v].norm());
  ASSERT_GT(largest, 0.0);
  for (std::size_t v = 0; v < x.size(); ++v) EXPECT_NEAR((f1[v] - f2[v]).norm(), 0.0, 1e-12 * largest) << "node " << v;
  EXPECT_EQ(whole->integrator->dt_s(), plain->integrator->dt_s());  // the same masses and stiffness

  // A nodule: only its elements' forces change (the forces of a single element's displacement).
  const auto base = build_organ(read_scene_file(liver_scene("base", soft, "[]")), kUntimed);
  const auto nodule =
      build_organ(read_scene_file(liver_scene("nodule", soft,
                                              R"([{"name": "nodule", "material": ")" + stiff +
                                                  R"(", "sphere": {"radius_m": 0.015, "random_center": {"seed": 11, "depth_m": [0.003, 0.02]}}}])")),
                  kUntimed);
  const RegionLayout& layout = nodule->regions;
  ASSERT_GT(layout.regions.at(0).elements, 0u);
  std::size_t inside_element = 0, outside_element = 0;
  for (std::size_t e = 0; e < layout.material_of_tet.size(); ++e) (layout.material_of_tet[e] ? inside_element : outside_element) = e;
  for (const auto& [e, changes] : {std::pair{inside_element, true}, std::pair{outside_element, false}}) {
    std::vector<Vec3> y = nodule->mesh->nodes;
    y[nodule->mesh->tets[e][0]] += Vec3(1e-4, -2e-4, 1e-4);
    std::vector<Vec3> a(y.size(), Vec3::Zero()), b(y.size(), Vec3::Zero());
    nodule->model->add_forces(y, a);
    base->model->add_forces(y, b);
    double diff = 0, size = 0;
    for (std::size_t v = 0; v < y.size(); ++v) {
      diff = std::max(diff, (a[v] - b[v]).norm());
      size = std::max(size, b[v].norm());
    }
    if (changes)
      EXPECT_GT(diff, 0.5 * size) << "element " << e << " is in the nodule (8x stiffer)";
    else
      EXPECT_LE(diff, 1e-9 * size) << "element " << e << " is outside the nodule";
  }
}

// A drawn centre: the same for the same seed, other places for other seeds, and what it promised:
// the sphere and the stated least depth of tissue above it lie inside the organ, it keeps clear of
// the fixed slab, and its elements are those whose centroid lies in it.
TEST(MaterialRegions, ADrawnSphereLiesInsideTheOrganAtTheStatedDepthAndIsTheSameForTheSameSeed) {
  auto mesh = std::make_shared<TetMesh>(read_tet_mesh(data("meshes/liver2.msh")));
  scale_mesh(*mesh, 0.08);
  const BoundarySurface boundary = extract_boundary(*mesh);
  Box slab = bounding_box(*mesh);
  slab.hi.z() = slab.lo.z() + 0.2 * (slab.hi.z() - slab.lo.z());
  RegionSpec r;
  r.name = "nodule";
  r.radius_m = 0.01;
  r.random_center = true;
  r.min_depth_m = 0.004;
  r.max_depth_m = 0.012;
  r.facing = {0, 0, 1};  // under the upper surface, where a probe palpates from
  std::set<std::array<double, 3>> centres;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    r.seed = seed;
    const RegionLayout a = lay_out_regions({r}, *mesh, boundary, slab, "s"), b = lay_out_regions({r}, *mesh, boundary, slab, "s");
    const PlacedRegion& p = a.regions.at(0);
    EXPECT_EQ(p.center_m, b.regions.at(0).center_m);
    EXPECT_EQ(a.material_of_tet, b.material_of_tet);
    centres.insert({p.center_m.x(), p.center_m.y(), p.center_m.z()});
    EXPECT_GE(p.depth_m, r.min_depth_m);
    EXPECT_LE(p.depth_m, r.max_depth_m);
    EXPECT_GT(p.center_m.z() - r.radius_m, slab.hi.z());
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0, 1);
    for (int k = 0; k < 100; ++k) {
      Vec3 d(g(rng), g(rng), g(rng));
      d.normalize();
      EXPECT_TRUE(inside(*mesh, p.center_m + 0.999 * (r.radius_m + r.min_depth_m) * d)) << "seed " << seed << ": tissue above the sphere";
    }
    // Under a surface facing up (within 60 degrees): straight up, the organ ends within
    // (radius + most depth) / cos 60 degrees.
    EXPECT_FALSE(inside(*mesh, p.center_m + Vec3(0, 0, 2 * (r.radius_m + r.max_depth_m) + 1e-3))) << "seed " << seed;
    for (std::size_t e = 0; e < mesh->tet_count(); ++e) {
      const auto& t = mesh->tets[e];
      const Vec3 c = 0.25 * (mesh->nodes[t[0]] + mesh->nodes[t[1]] + mesh->nodes[t[2]] + mesh->nodes[t[3]]);
      EXPECT_EQ(a.material_of_tet[e] == 1, (c - p.center_m).norm() <= r.radius_m);
    }
  }
  EXPECT_GE(centres.size(), 6u);
}

TEST(MaterialRegions, ScenesNameTheRegionFieldThatIsWrong) {
  const std::string stiff = isotropic("stiff2", 40e3, 1100), soft = isotropic("soft2", 5e3, 1060);
  const auto message = [&](const std::string& regions) {
    try {
      build_organ(read_scene_file(liver_scene("bad", soft, regions)), kUntimed);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string m = R"("name": "n", "material": ")" + stiff + R"(", )";
  EXPECT_NE(message(R"([{)" + m + R"("sphere": {"radius_m": 0.01, "center_m": [0, 0, 0]}, "box": {"lo_m": [0,0,0], "hi_m": [1,1,1]}}])")
                .find("organ.regions[0].sphere: a region is one of"),
            std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("cylinder": {}}])").find("organ.regions[0].cylinder: unknown field"), std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("sphere": {"radius_m": 0.01}}])").find("organ.regions[0].sphere.center_m"), std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("sphere": {"radius_m": -1, "center_m": [0, 0, 0]}}])").find("organ.regions[0].sphere.radius_m"),
            std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("box": {"lo_m": [0, 0, 0], "hi_m": [1, -1, 1]}}])").find("organ.regions[0].box.hi_m"), std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("sphere": {"radius_m": 0.01, "center_m": [5, 5, 5]}}])").find("organ.regions[0].sphere: 'n' holds no element"),
            std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("sphere": {"radius_m": 0.01, "random_center": {"seed": 1, "depth_m": [0.5, 0.6]}}}])")
                .find("organ.regions[0].sphere.random_center.depth_m: no place"),
            std::string::npos);
  EXPECT_NE(message(R"([{)" + m + R"("sphere": {"radius_m": 0.01, "center_m": [0, 0, 0]}}, {)" + m + R"("box": {"lo_m": [0,0,0], "hi_m": [1,1,1]}}])")
                .find("organ.regions[1].name: 'n' is used twice"),
            std::string::npos);
  const std::string other_q = isotropic("stiff-q", 40e3, 1100, R"({"shear_q": 9})");
  const std::string soft_q = isotropic("soft-q", 5e3, 1060, R"({"shear_q": 4.8})");
  try {
    build_organ(read_scene_file(
                    liver_scene("q", soft_q, R"([{"name": "n", "material": ")" + other_q + R"(", "box": {"lo_m": [-9,-9,-9], "hi_m": [9,9,9]}}])")),
                kUntimed);
    ADD_FAILURE() << "a region with its own relaxation was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stiff-q.json: viscoelasticity: differs from the organ's"), std::string::npos) << e.what();
  }
}
