// Random strokes through the liver (docs/CUTTING.md, "Tests"): after every sweep the mesh is  // SPDX-License-Identifier: Apache-2.0
// valid and conforming, volume and mass are kept, and the boundary surface brought along the cut
// in place is the one extracted from the whole cut mesh; each cut organ then runs on both
// integrators.
#include <algorithm>
#include <iostream>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "viscera/tissue/cutting/boundary_update.hpp"
#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/integrator/mass_scaling.hpp"
#include "viscera/tissue/integrator/stable_step.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/mesh_validation.hpp"

#include "cutting_support.hpp"
#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;
using test::expect_valid_conforming;
using test::node_connected_components;
using test::total;

namespace {

// A triangle as a set of oriented triangles: rotated so its smallest node comes first.
std::array<std::int32_t, 4> canonical(const Triangle& t, std::int32_t owner) {
  const int k = static_cast<int>(std::min_element(t.begin(), t.end()) - t.begin());
  return {t[k], t[(k + 1) % 3], t[(k + 2) % 3], owner};
}

std::set<std::array<std::int32_t, 4>> triangle_set(const BoundarySurface& s) {
  std::set<std::array<std::int32_t, 4>> out;
  for (std::size_t k = 0; k < s.triangles.size(); ++k) out.insert(canonical(s.triangles[k], s.owner_tet[k]));
  return out;
}

}  // namespace

TEST(CuttingFuzz, RandomStrokesThroughTheLiverKeepEveryInvariant) {
  // Strokes of random blades (position, orientation, length, direction, a curve out of the
  // blade's plane) through the liver deformed by a random affine map: after every sweep the mesh
  // is valid and conforming, volume and mass are those of the organ before, and every new
  // element's quality and own stable step are measured against the organ's worst.
  const auto liver = test::liver2();
  const Box box = bounding_box(*liver);
  const double size = (box.hi - box.lo).norm();
  const Mat6 D = test::soft_tissue();
  const double density = 1000.0;
  const GpsModel original_model(liver, {D});
  const std::vector<double> rho0(liver->tet_count(), density);
  const double worst_step_before = critical_time_step(original_model, rho0).dt_s;
  double worst_quality_before = 1.0;
  for (const Tet& t : liver->tets)
    worst_quality_before =
        std::min(worst_quality_before, tet_quality(liver->nodes[t[0]], liver->nodes[t[1]], liver->nodes[t[2]], liver->nodes[t[3]]));
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n;
  const int organs = 12, strokes_per_organ = 4, sweeps_per_stroke = 40;
  std::size_t boundary_updates = 0, boundary_triangles_changed = 0;
  std::size_t sweeps = 0, splits = 0, copies = 0, snapped = 0, kept = 0;
  double worst_quality = 1.0, worst_step = 1e9, worst_added = 0.0;
  int max_pieces = 1, smallest_piece = 1 << 30;
  for (int organ = 0; organ < organs; ++organ) {
    TetMesh m = *liver;
    const double volume0 = mesh_volume(m), mass0 = total(lumped_masses(m, density));
    Mat3 F = Mat3::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += 0.1 * n(rng);
    MeshCutter cutter(m);
    BoundarySurface surface = extract_boundary(m);
    for (int stroke = 0; stroke < strokes_per_organ; ++stroke) {
      const Vec3 centre = box.lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(box.hi - box.lo);
      const Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
      Vec3 travel = Vec3(n(rng), n(rng), n(rng));
      travel = (travel - travel.dot(axis) * axis).normalized();  // in the blade's plane...
      const Vec3 bend = axis.cross(travel) * 0.3 * n(rng);  // ...bent out of it along the stroke
      const double length = size * (0.1 + 0.6 * u(rng)), reach = size * (0.2 + 0.6 * u(rng));
      const auto blade = [&](double t) {
        const Vec3 mid = centre + (t - 0.5) * reach * travel + (t - 0.5) * (t - 0.5) * reach * bend;
        return std::pair<Vec3, Vec3>{mid - 0.5 * length * axis, mid + 0.5 * length * axis};
      };
      for (int k = 0; k < sweeps_per_stroke; ++k) {
        const auto [a0, b0] = blade(static_cast<double>(k) / sweeps_per_stroke);
        const auto [a1, b1] = blade(static_cast<double>(k + 1) / sweeps_per_stroke);
        std::vector<Vec3> x = m.nodes;
        for (auto& p : x) p = F * p;
        const std::size_t tets_before = m.tets.size();
        const CutChange c = cutter.cut({F * a0, F * b0, F * a1, F * b1}, x, stroke);
        ++sweeps;
        splits += c.split_edges;
        copies += c.duplicated_nodes;
        snapped += c.snapped_nodes;
        kept += c.kept_joined;
        ASSERT_EQ(c.origin.size(), m.tets.size());
        ASSERT_EQ(c.first_new_node + c.new_nodes.size(), m.nodes.size());
        extend_nodal(c, x);
        for (std::size_t i = c.first_new_node; i < x.size(); ++i) {
          ASSERT_TRUE(x[i].allFinite());
          ASSERT_LT((x[i] - F * m.nodes[i]).norm(), 1e-12 * size) << "a new node's position is not its rest position mapped";
        }
        for (std::size_t e = 0; e < m.tets.size(); ++e) {
          if (c.origin[e] == static_cast<std::int32_t>(e) && e < tets_before) continue;
          const Tet& t = m.tets[e];
          worst_quality = std::min(worst_quality, tet_quality(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]));
        }
        const BoundaryChange bc = update_boundary(surface, cutter, c);
        if (!c.topology_changed()) continue;
        ++boundary_updates;
        boundary_triangles_changed += bc.removed_triangles + bc.added_triangles;
        const BoundarySurface whole = extract_boundary(m);
        ASSERT_EQ(triangle_set(surface), triangle_set(whole)) << "the boundary brought along the cut is not the cut mesh's";
        ASSERT_EQ(surface.nodes, whole.nodes);
        expect_valid_conforming(m);
        if (HasFatalFailure()) return;
        ASSERT_NEAR(mesh_volume(m), volume0, 1e-9 * volume0);
        ASSERT_NEAR(total(lumped_masses(m, density)), mass0, 1e-12 * mass0);
      }
    }
    int pieces = 0;
    const auto comp = node_connected_components(m, &pieces);
    max_pieces = std::max(max_pieces, pieces);
    std::vector<int> piece_tets(static_cast<std::size_t>(pieces), 0);
    for (const int c : comp) ++piece_tets[static_cast<std::size_t>(c)];
    for (const int k : piece_tets) smallest_piece = std::min(smallest_piece, k);
    const auto mesh = std::make_shared<TetMesh>(m);
    const GpsModel cut_model(mesh, {D});
    std::vector<double> rho(m.tet_count(), density);
    worst_step = std::min(worst_step, critical_time_step(cut_model, rho).dt_s);
    // The rule that keeps the step: local mass scaling of the new elements to the organ's step.
    std::vector<std::int32_t> made;
    for (std::size_t e = 0; e < m.tet_count(); ++e)
      if (e >= liver->tet_count() || m.tets[e] != liver->tets[e]) made.push_back(static_cast<std::int32_t>(e));
    const double added = hold_element_steps(cut_model, rho, made, worst_step_before);
    worst_added = std::max(worst_added, added / total(lumped_masses(m, density)));
    EXPECT_GE(critical_time_step(cut_model, rho).dt_s, worst_step_before * (1 - 1e-12));
    std::vector<Vec3> x = m.nodes, f(x.size(), Vec3::Zero());
    for (auto& p : x) p = F * p;
    cut_model.add_forces(x, f);
    for (const Vec3& fi : f) ASSERT_TRUE(fi.allFinite());
    // Both integrators run the cut organ hanging from its top under gravity (free pieces fall).
    BoundaryConditions bc;
    bc.gravity_m_s2 = Vec3(0, 0, -9.81);
    bc.fixed_nodes = nodes_in_box(m, Box{Vec3(-1, -1, box.hi.z() - 0.02), Vec3(1, 1, 1)});
    ExplicitIntegrator explicit_path(cut_model, rho, bc);
    State st = State::at_rest(m);
    for (int i = 0; i < 20; ++i) ASSERT_NO_THROW(explicit_path.step(st));
    ImplicitOptions io;
    io.dt_s = 1e-3;
    ImplicitIntegrator implicit_path(cut_model, rho, bc, io);
    for (int i = 0; i < 2; ++i) ASSERT_NO_THROW(implicit_path.step(st));
    for (const Vec3& p : st.x) ASSERT_TRUE(p.allFinite());
  }
  EXPECT_GT(splits, 1000u);
  EXPECT_GT(copies, 100u);
  EXPECT_GT(max_pieces, 1);
  std::cout << "[ figure ] fuzz: " << sweeps << " sweeps in " << organs * strokes_per_organ << " strokes, " << splits << " edges split, " << snapped
            << " nodes snapped, " << copies << " copies, " << kept << " tetrahedra kept joined, up to " << max_pieces
            << " pieces (smallest: " << smallest_piece << " tets); worst new element quality " << worst_quality << " (organ's worst "
            << worst_quality_before << "), worst element step " << worst_step * 1e3 << " ms (organ's " << worst_step_before * 1e3
            << " ms); held there by adding at most " << worst_added * 100 << "% of the organ's mass to new elements; the boundary followed "
            << boundary_updates << " changes in place (" << boundary_triangles_changed
            << " triangles removed or added), each equal to the extracted one\n";
}

namespace {

TEST(CuttingFuzz, TenThousandRandomSweepsFollowedInPlaceByTheModelAndBothIntegrators) {
  // As the libFuzzer target (tests/fuzz/cutting_fuzz.cpp) but without the sanitizers, so that
  // every change is followed: random sweeps through a 4 x 3 x 3 cm box (216 tets) held at its
  // bottom under gravity, their ends on a quarter-spacing grid (through nodes, along edges, in the
  // planes of faces), 32 per organ, the snap fraction drawn per organ. A viscoelastic GPS, the
  // explicit and the implicit (CHOLMOD) integrator follow every change in place, in the moving
  // organ's positions. After each change: the mesh valid and conforming, rest volume and mass
  // kept, the implicit masses summing to the box's mass, positions finite. After each organ:
  // 5 explicit steps and a backward Euler step, finite.
  const TetMesh box = make_box_mesh(Vec3(0, 0, 0), Vec3(0.04, 0.03, 0.03), 4, 3, 3);
  const double volume0 = mesh_volume(box), density = 1000.0, mass0 = density * volume0;
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.3;
  o.mechanisms.viscous.omega_rad_s = {2.0, 200.0};
  o.mechanisms.viscous.shear_weight = {0.2, 0.2};
  o.mechanisms.viscous.bulk_weight = {0.0, 0.0};
  std::mt19937_64 rng(35);
  std::uniform_int_distribution<int> grid(0, 25), step(-2, 2), coin(0, 3);
  const auto point = [&]() -> Vec3 {
    const double x = grid(rng) - 4.0, y = grid(rng) - 4.0, z = grid(rng) - 4.0;
    return 0.0025 * Vec3(x, y, z);
  };
  std::size_t sweeps = 0, changes = 0, organs = 0, pieces_max = 1;
  while (sweeps < 10000) {
    const auto mesh = std::make_shared<TetMesh>(box);
    MeshCutter cutter(*mesh, CutOptions{0.05 * static_cast<double>(1 + organs % 7)});
    GpsModel gps(mesh, {test::soft_tissue()}, {}, o);
    BoundaryConditions bc;
    bc.gravity_m_s2 = Vec3(0, 0, -9.81);
    bc.fixed_nodes = nodes_in_box(*mesh, Box{Vec3(-1, -1, -1), Vec3(1, 1, 1e-9)});
    ExplicitIntegrator explicit_path(gps, std::vector<double>(mesh->tet_count(), density), bc);
    ImplicitOptions io;
    io.dt_s = 1e-3;
    ImplicitIntegrator implicit_path(gps, std::vector<double>(mesh->tet_count(), density), bc, io);
    State se = State::at_rest(*mesh), si = State::at_rest(*mesh);
    se.memory.assign(gps.memory_size(), 0.0);
    for (int k = 0; k < 3; ++k) explicit_path.step(se);  // moving, its memory in use
    BladeSweep sweep{};
    for (int k = 0; k < 32; ++k, ++sweeps) {
      if (k == 0 || coin(rng) == 0) {  // a new blade, or the last one going on
        sweep.a0 = point();
        sweep.b0 = point();
      } else {
        sweep.a0 = sweep.a1;
        sweep.b0 = sweep.b1;
      }
      const double mx = step(rng), my = step(rng), mz = step(rng);
      const Vec3 move = 0.0025 * Vec3(mx, my, mz);
      sweep.a1 = sweep.a0 + move;
      sweep.b1 = sweep.b0 + move;
      const CutChange c = cutter.cut(sweep, se.x, static_cast<std::int32_t>(coin(rng)));
      if (!c.topology_changed()) continue;
      ++changes;
      gps.follow_edit(c.edit(), se.memory);
      explicit_path.follow_edit(c.edit(), se);
      implicit_path.follow_edit(c.edit(), si);
      ASSERT_NO_THROW(validate_mesh(*mesh)) << "organ " << organs << ", sweep " << k;
      ASSERT_EQ(overshared_faces(*mesh), 0u) << "organ " << organs << ", sweep " << k;
      ASSERT_NEAR(mesh_volume(*mesh), volume0, 1e-12 * volume0);
      ASSERT_NEAR(total(implicit_path.masses()), mass0, 1e-12 * mass0);
      ASSERT_GE(total(explicit_path.masses()), mass0 * (1 - 1e-12));  // the step rule only adds inertia
      for (const Vec3& p : se.x) ASSERT_TRUE(p.allFinite());
    }
    for (int k = 0; k < 5; ++k) ASSERT_NO_THROW(explicit_path.step(se)) << "organ " << organs;
    ASSERT_NO_THROW(implicit_path.step(si)) << "organ " << organs;
    for (const Vec3& p : se.x) ASSERT_TRUE(p.allFinite());
    for (const Vec3& p : si.x) ASSERT_TRUE(p.allFinite());
    int pieces = 0;
    node_connected_components(*mesh, &pieces);
    pieces_max = std::max<std::size_t>(pieces_max, static_cast<std::size_t>(pieces));
    ++organs;
  }
  EXPECT_GT(changes, 1000u);
  std::cout << "[ figure ] " << sweeps << " random sweeps through " << organs << " boxes, " << changes
            << " changes of the mesh followed in place by the model and both integrators, up to " << pieces_max
            << " pieces; 0 crashes, 0 non-finite values\n";
}

}  // namespace
