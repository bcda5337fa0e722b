// Cutting (docs/CUTTING.md): a blade's swept surface splits the tetrahedra it crosses, the nodes  // SPDX-License-Identifier: Apache-2.0
// along it are duplicated where the mesh comes apart, and nothing is lost. Checked against
// geometry (which side of the cut every tetrahedron lies on), conservation, linear FE on the cut
// mesh, rigid motions, and a model that lived its whole history on the cut mesh.
#include <iostream>
#include <map>
#include <numeric>
#include <set>

#include <gtest/gtest.h>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/fem/finite_element_model.hpp"
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

// A 10 x 2 x 2 cm bar, 1 cm cubes, 240 tetrahedra.
TetMesh bar() { return make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2); }

// A blade along y from y0 to y1 at x = xc, drawn down through z from above the bar to below it
// in `ticks` sweeps (one stroke), cutting the mesh at rest.
std::vector<CutChange> draw_blade(MeshCutter& cutter, double xc, double y0, double y1, int ticks, std::int32_t stroke = 0) {
  std::vector<CutChange> changes;
  const double z_top = 0.03, z_bottom = -0.01;
  for (int i = 0; i < ticks; ++i) {
    const double za = z_top + (z_bottom - z_top) * i / ticks, zb = z_top + (z_bottom - z_top) * (i + 1) / ticks;
    const BladeSweep sweep{Vec3(xc, y0, za), Vec3(xc, y1, za), Vec3(xc, y0, zb), Vec3(xc, y1, zb)};
    const std::vector<Vec3> x = cutter.mesh().nodes;  // the mesh at rest: current = rest
    changes.push_back(cutter.cut(sweep, x, stroke));
  }
  return changes;
}

double surface_area(const TetMesh& m) {
  double a = 0.0;
  for (const Triangle& t : extract_boundary(m).triangles) a += 0.5 * (m.nodes[t[1]] - m.nodes[t[0]]).cross(m.nodes[t[2]] - m.nodes[t[0]]).norm();
  return a;
}

}  // namespace

TEST(Cutting, ABarCutThroughFallsIntoTwoPiecesOnEitherSideOfTheBlade) {
  TetMesh m = bar();
  const double volume0 = mesh_volume(m), mass0 = total(lumped_masses(m, 1000.0)), area0 = surface_area(m);
  MeshCutter cutter(m);
  const double xc = 0.0537;  // between node planes: edges along x are crossed at s = 0.37
  const auto changes = draw_blade(cutter, xc, -0.01, 0.03, 20);
  std::size_t splits = 0, copies = 0;
  for (const auto& c : changes) {
    splits += c.split_edges;
    copies += c.duplicated_nodes;
  }
  expect_valid_conforming(m);
  int pieces = 0;
  const auto comp = node_connected_components(m, &pieces);
  EXPECT_EQ(pieces, 2);
  // Each tetrahedron lies on one side of the blade's plane (snapping moves the cut by at most
  // snap_fraction of an edge: 0.2 x the longest edge, sqrt(3) cm).
  const double tol = 0.2 * std::sqrt(3.0) * 0.01 + 1e-12;
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    double lo = 1e9, hi = -1e9;
    for (const auto v : m.tets[e]) {
      lo = std::min(lo, m.nodes[v].x() - xc);
      hi = std::max(hi, m.nodes[v].x() - xc);
    }
    EXPECT_FALSE(lo < -tol && hi > tol) << "tet " << e << " straddles the cut";
    const Vec3 c = (m.nodes[m.tets[e][0]] + m.nodes[m.tets[e][1]] + m.nodes[m.tets[e][2]] + m.nodes[m.tets[e][3]]) / 4;
    EXPECT_EQ(comp[e], comp[0] == 0 ? (c.x() < xc ? 0 : 1) : (c.x() < xc ? 1 : 0)) << "tet " << e;
  }
  EXPECT_NEAR(mesh_volume(m), volume0, 1e-12 * volume0);
  EXPECT_NEAR(total(lumped_masses(m, 1000.0)), mass0, 1e-12 * mass0);
  // Every edge with an extent in x is crossed at s = 0.37 (no snapping): the cut is the plane
  // itself, and the surface grows by the bar's section on each side.
  EXPECT_NEAR(surface_area(m) - area0, 2 * 0.02 * 0.02, 1e-12);
  std::cout << "[ figure ] bar cut through: " << m.tets.size() << " tets (240 before), " << splits << " edges split, " << copies
            << " nodes duplicated\n";

  // No force crosses the cut: stretching the right piece leaves the left one without force.
  const auto mesh = std::make_shared<TetMesh>(m);
  const GpsModel gps(mesh, {test::soft_tissue()});
  std::vector<Vec3> x = m.nodes, f(x.size(), Vec3::Zero());
  for (std::size_t e = 0; e < m.tets.size(); ++e)
    if (comp[e] != comp[0])
      for (const auto v : m.tets[e]) x[v].x() = xc + 1.01 * (m.nodes[v].x() - xc) + 0.0;
  gps.add_forces(x, f);
  double left = 0.0, right = 0.0;
  for (std::size_t e = 0; e < m.tets.size(); ++e)
    for (const auto v : m.tets[e]) (comp[e] == comp[0] ? left : right) = std::max(comp[e] == comp[0] ? left : right, f[v].norm());
  EXPECT_EQ(left, 0.0);
  EXPECT_GT(right, 0.0);
}

TEST(Cutting, ANotchedBarInTensionHasTheForcesOfLinearFeOnTheCutMesh) {
  TetMesh m = bar();
  const double area0 = surface_area(m);
  MeshCutter cutter(m);
  const auto changes = draw_blade(cutter, 0.0537, -0.01, 0.0137, 20);  // through two thirds of the height
  std::size_t copies = 0;
  for (const auto& c : changes) copies += c.duplicated_nodes;
  expect_valid_conforming(m);
  int pieces = 0;
  node_connected_components(m, &pieces);
  EXPECT_EQ(pieces, 1);  // notched, not cut off
  EXPECT_GT(copies, 0u);
  // The notch opened where the blade passed completely: between the last row of elements it
  // crossed whole (y up to 1 cm) and where it stopped (1.37 cm), over the bar's 2 cm width.
  const double opened = (surface_area(m) - area0) / 2;
  EXPECT_GE(opened, 0.02 * 0.01 - 1e-12);
  EXPECT_LE(opened, 0.02 * 0.0137 + 1e-12);
  std::cout << "[ figure ] notch: opened " << opened * 1e4 << " cm^2 of the 2.74 cm^2 the blade swept in the bar, " << cutter.pending_faces()
            << " faces still closed at its front\n";

  const auto mesh = std::make_shared<TetMesh>(m);
  const Mat6 D = test::soft_tissue();
  const FiniteElementModel fe(mesh, FeKind::linear, {D});
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n;
  std::vector<Vec3> x = m.nodes;
  for (auto& p : x) p += 1e-10 * Vec3(n(rng), n(rng), n(rng)) + Vec3(1e-10 * p.x() / 0.1, 0, 0);
  std::vector<Vec3> ff(x.size(), Vec3::Zero());
  fe.add_forces(x, ff);
  for (const GpsVariant variant : {GpsVariant::paper, GpsVariant::energy_consistent}) {
    GpsOptions o;
    o.variant = variant;
    const GpsModel gps(mesh, {D}, {}, o);
    std::vector<Vec3> fg(x.size(), Vec3::Zero());
    gps.add_forces(x, fg);
    double num = 0, den = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      num += (fg[i] - ff[i]).squaredNorm();
      den += ff[i].squaredNorm();
    }
    EXPECT_LT(std::sqrt(num / den), 1e-6) << gps.name();
    std::cout << "[ figure ] notched bar, " << gps.name() << " vs linear FE on the cut mesh: relative force error " << std::sqrt(num / den) << "\n";
  }
}

TEST(Cutting, TheCutGpsStaysRotationInvariant) {
  TetMesh m = bar();
  MeshCutter cutter(m);
  draw_blade(cutter, 0.0537, -0.01, 0.0137, 20);
  const auto mesh = std::make_shared<TetMesh>(m);
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.5;
  const GpsModel gps(mesh, {test::soft_tissue()}, {}, o);
  std::mt19937_64 rng(3);
  const Mat3 R = test::random_rotation(rng);
  std::vector<Vec3> stretched = m.nodes, rotated = m.nodes, x = m.nodes;
  for (auto& p : stretched) p.x() *= 1.01;
  for (std::size_t i = 0; i < x.size(); ++i) {
    rotated[i] = R * m.nodes[i];
    x[i] = R * stretched[i];
  }
  std::vector<Vec3> f_rigid(x.size(), Vec3::Zero()), f_stretch(x.size(), Vec3::Zero()), f_both(x.size(), Vec3::Zero());
  gps.add_forces(rotated, f_rigid);
  gps.add_forces(stretched, f_stretch);
  gps.add_forces(x, f_both);
  double rigid = 0, scale = 0, rot_err = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    rigid = std::max(rigid, f_rigid[i].norm());
    scale = std::max(scale, f_stretch[i].norm());
    rot_err = std::max(rot_err, (f_both[i] - R * f_stretch[i]).norm());
  }
  EXPECT_LT(rigid / scale, 1e-11);
  EXPECT_LT(rot_err / scale, 1e-11);
}

TEST(Cutting, ChildrenCarryTheirParentsViscoelasticState) {
  // A uniform strain history on the whole bar, then a cut: the children's memory, carried from
  // their parents, equals the memory of a model that lived the same history on the cut mesh.
  TetMesh before_mesh = bar();
  TetMesh m = before_mesh;
  MeshCutter cutter(m);
  const auto changes = draw_blade(cutter, 0.0537, -0.01, 0.03, 1);  // one sweep: one change
  ASSERT_EQ(changes.size(), 1u);
  ASSERT_GT(changes[0].split_edges, 0u);
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.mechanisms.viscous.omega_rad_s = {2.0, 40.0, 800.0};
  o.mechanisms.viscous.shear_weight = {0.1, 0.15, 0.2};
  const GpsModel before(std::make_shared<TetMesh>(before_mesh), {test::soft_tissue()}, {}, o);
  const GpsModel after(std::make_shared<TetMesh>(m), {test::soft_tissue()}, {}, o);
  Mat3 E;
  E << 2.0, 0.4, -0.3, 0.4, -1.0, 0.6, -0.3, 0.6, 0.5;
  std::vector<double> mb(before.memory_size(), 0.0), ma(after.memory_size(), 0.0);
  const double dt = 1e-3;
  for (int step = 1; step <= 50; ++step) {
    const Mat3 F = Mat3::Identity() + 1e-7 * std::sin(0.2 * step) * E;  // small: the strain map is the linear one
    std::vector<Vec3> xb = before_mesh.nodes, xa = m.nodes, fb(xb.size(), Vec3::Zero()), fa(xa.size(), Vec3::Zero());
    for (auto& p : xb) p = F * p;
    for (auto& p : xa) p = F * p;
    before.add_forces(xb, fb, MemoryUpdate{mb, mb, dt});
    after.add_forces(xa, fa, MemoryUpdate{ma, ma, dt});
  }
  const std::vector<double> carried = after.memory_from(before, mb, changes[0].origin);
  double num = 0, den = 0;
  for (std::size_t i = 0; i < ma.size(); ++i) {
    num = std::max(num, std::fabs(carried[i] - ma[i]));
    den = std::max(den, std::fabs(ma[i]));
  }
  EXPECT_GT(den, 0.0);
  EXPECT_LT(num / den, 1e-6);
  std::cout << "[ figure ] memory carried into cut tetrahedra vs lived on the cut mesh: max relative difference " << num / den << "\n";
}

TEST(Cutting, APieceCutFreeFallsUnderGravityOnTheExplicitAndImplicitPaths) {
  // The bar hangs from its left end and is cut through: the right piece's centre of mass falls
  // as a free body (no force crosses the cut, internal forces sum to zero), exactly as each
  // integrator moves a free particle; the left piece stays held.
  TetMesh m = bar();
  MeshCutter cutter(m);
  draw_blade(cutter, 0.0537, -0.01, 0.03, 20);
  int pieces = 0;
  const auto comp = node_connected_components(m, &pieces);
  ASSERT_EQ(pieces, 2);
  const auto mesh = std::make_shared<TetMesh>(m);
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.3;
  const GpsModel gps(mesh, {test::soft_tissue()}, {}, o);
  const double density = 1000.0, g = 9.81;
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -g);
  bc.fixed_nodes = nodes_in_box(m, Box{Vec3(-1, -1, -1), Vec3(1e-9, 1, 1)});
  std::vector<char> free_node(m.nodes.size(), 0);
  for (std::size_t e = 0; e < m.tets.size(); ++e)
    if (comp[e] != comp[0])
      for (const auto v : m.tets[e]) free_node[v] = 1;
  const std::vector<double> masses = lumped_masses(m, density);
  const auto free_centre_z = [&](const State& st) {
    double mz = 0, mass = 0;
    for (std::size_t i = 0; i < st.x.size(); ++i)
      if (free_node[i]) {
        mz += masses[i] * st.x[i].z();
        mass += masses[i];
      }
    return mz / mass;
  };
  {
    ExplicitIntegrator integrator(gps, std::vector<double>(m.tet_count(), density), bc);
    State st = State::at_rest(m);
    const double z0 = free_centre_z(st), dt = integrator.dt_s();
    const int n = 200;
    for (int i = 0; i < n; ++i) integrator.step(st);
    // Symplectic Euler from rest: v_k = k g dt, z_n = z0 - g dt^2 n (n + 1) / 2.
    EXPECT_NEAR(free_centre_z(st), z0 - g * dt * dt * n * (n + 1) / 2, 1e-9);
    for (const auto v : bc.fixed_nodes) EXPECT_EQ(st.x[v], m.nodes[v]);
  }
  {
    ImplicitOptions io;
    io.dt_s = 1e-3;
    ImplicitIntegrator integrator(gps, std::vector<double>(m.tet_count(), density), bc, io);
    State st = State::at_rest(m);
    const double z0 = free_centre_z(st);
    for (int i = 0; i < 5; ++i) integrator.step(st);
    // Backward Euler from rest: v_k = k g dt, z_n = z0 - g dt^2 n (n + 1) / 2 as well.
    EXPECT_NEAR(free_centre_z(st), z0 - g * io.dt_s * io.dt_s * 15, 1e-9);
    for (const Vec3& p : st.x) ASSERT_TRUE(p.allFinite());
  }
}

TEST(Cutting, AModelFollowingTheCutInPlaceEqualsOneBuiltOnTheCutMesh) {
  // The running organ's model follows each sweep (only the changed elements recalibrated); a
  // model built from scratch on the final mesh, its memory carried from a model of the mesh
  // before, must give the same forces and memory bit for bit.
  const auto live = std::make_shared<TetMesh>(bar());
  const TetMesh before_mesh = *live;
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.4;
  o.mechanisms.viscous.omega_rad_s = {5.0, 300.0};
  o.mechanisms.viscous.shear_weight = {0.2, 0.3};
  o.mechanisms.viscous.bulk_weight = {0.1, 0.05};
  const Mat6 D = test::soft_tissue();
  GpsModel model(live, {D, 2.0 * D}, std::vector<std::uint16_t>(live->tet_count(), 1), o);
  const GpsModel before(std::make_shared<TetMesh>(before_mesh), {D, 2.0 * D}, std::vector<std::uint16_t>(live->tet_count(), 1), o);
  std::vector<double> memory(model.memory_size(), 0.0);
  std::vector<Vec3> x = live->nodes, f(x.size(), Vec3::Zero());
  for (auto& p : x) p = Vec3(1.001 * p.x(), p.y() - 0.002 * p.x(), p.z());
  model.add_forces(x, f, MemoryUpdate{memory, memory, 1e-3});
  const std::vector<double> memory_before = memory;
  MeshCutter cutter(*live);
  std::vector<std::int32_t> origin(live->tet_count());
  std::iota(origin.begin(), origin.end(), 0);
  for (int k = 0; k < 10; ++k) {  // a stroke through the bar, the model following every sweep
    const double z0 = 0.03 - 0.004 * k, z1 = z0 - 0.004;
    const double xc = 0.0537;
    const CutChange c = cutter.cut({Vec3(xc, -0.01, z0), Vec3(xc, 0.03, z0), Vec3(xc, -0.01, z1), Vec3(xc, 0.03, z1)}, x, 0);
    extend_nodal(c, x);
    model.follow_edit(c.edit(), memory);
    std::vector<std::int32_t> next(c.origin.size());
    for (std::size_t e = 0; e < next.size(); ++e) next[e] = origin[static_cast<std::size_t>(c.origin[e])];
    origin = next;
  }
  ASSERT_GT(live->tet_count(), before_mesh.tet_count());
  const GpsModel fresh(std::make_shared<TetMesh>(*live), {D, 2.0 * D}, std::vector<std::uint16_t>(live->tet_count(), 1), o);
  const std::vector<double> carried = fresh.memory_from(before, memory_before, origin);
  ASSERT_EQ(carried.size(), memory.size());
  // The same elements, calibrated by the same code: the elastic forces are bit for bit equal.
  std::vector<Vec3> fa(x.size(), Vec3::Zero()), fb(x.size(), Vec3::Zero());
  model.add_forces(x, fa);
  fresh.add_forces(x, fb);
  for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(fa[i], fb[i]) << "node " << i;
  // Memory carried sweep by sweep (a child of a child) or at once differs by rounding only.
  double worst = 0, scale = 0;
  for (std::size_t i = 0; i < memory.size(); ++i) {
    worst = std::max(worst, std::fabs(carried[i] - memory[i]));
    scale = std::max(scale, std::fabs(carried[i]));
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(worst, 1e-12 * scale);
  std::vector<double> ma = memory, mb = carried;
  fa.assign(x.size(), Vec3::Zero());
  fb.assign(x.size(), Vec3::Zero());
  model.add_forces(x, fa, MemoryUpdate{ma, ma, 1e-3});
  fresh.add_forces(x, fb, MemoryUpdate{mb, mb, 1e-3});
  double fmax = 0, fdiff = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    fmax = std::max(fmax, fb[i].norm());
    fdiff = std::max(fdiff, (fa[i] - fb[i]).norm());
  }
  EXPECT_LT(fdiff, 1e-12 * fmax);
}

TEST(Cutting, AnOrganCutWhileItSwingsKeepsItsMassAndMomentumAndGainsNoEnergy) {
  // The bar hangs from its left end and swings under gravity while a blade cuts it through,
  // one sweep every 5 explicit steps; the model and the integrator follow each sweep in place.
  // At every cut: momentum is kept (split masses carry interpolated velocities; added inertia
  // keeps its node's momentum), the total energy (kinetic, elastic, gravity) does not go up, the
  // lumped masses are those of the mesh as it now is, and no element's own step is below the
  // organ's. Afterwards the run goes on, the free piece falling.
  const auto mesh = std::make_shared<TetMesh>(bar());
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.3;
  GpsModel model(mesh, {200.0 * test::soft_tissue()}, {}, o);  // 1 MPa: it sags millimetres, not metres
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  bc.fixed_nodes = nodes_in_box(*mesh, Box{Vec3(-1, -1, -1), Vec3(1e-9, 1, 1)});
  ExplicitIntegrator integrator(model, std::vector<double>(mesh->tet_count(), 1000.0), bc);
  State st = State::at_rest(*mesh);
  for (int i = 0; i < 300; ++i) integrator.step(st);
  const auto energy = [&] { return integrator.kinetic_energy(st) + model.energy(st.x) + integrator.gravity_energy(st.x); };
  const auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < st.v.size(); ++i) p += integrator.masses()[i] * st.v[i];
    return p;
  };
  MeshCutter cutter(*mesh);
  const double xc = 0.0537;
  double worst_rise = -1e300, added = 0.0;
  int cuts = 0;
  for (int k = 0; k < 20; ++k) {
    for (int i = 0; i < 5; ++i) integrator.step(st);
    const double z0 = 0.03 - 0.002 * k, z1 = z0 - 0.002;  // the blade goes down with the bar's sag
    const double e0 = energy(), scale = integrator.kinetic_energy(st) + std::fabs(model.energy(st.x));
    const Vec3 p0 = momentum();
    const CutChange c = cutter.cut({Vec3(xc, -0.01, z0), Vec3(xc, 0.03, z0), Vec3(xc, -0.01, z1), Vec3(xc, 0.03, z1)}, st.x, 0);
    if (!c.topology_changed()) continue;
    ++cuts;
    model.follow_edit(c.edit(), st.memory);
    added += integrator.follow_edit(c.edit(), st);
    ASSERT_EQ(st.x.size(), mesh->nodes.size());
    worst_rise = std::max(worst_rise, (energy() - e0) / scale);
    EXPECT_LT((momentum() - p0).norm(), 1e-12 * std::max(p0.norm(), 1e-30) + 1e-18);
  }
  EXPECT_GE(cuts, 3);
  EXPECT_LE(worst_rise, 1e-9);
  const std::vector<double> lumped = lumped_masses(*mesh, integrator.mass_scaling().density_kg_m3);
  for (std::size_t i = 0; i < lumped.size(); ++i) ASSERT_NEAR(integrator.masses()[i], lumped[i], 1e-12 * lumped[i]) << "node " << i;
  EXPECT_GE(critical_time_step(model, integrator.mass_scaling().density_kg_m3).dt_s, integrator.element_step_s() * (1 - 1e-12));
  int pieces = 0;
  node_connected_components(*mesh, &pieces);
  EXPECT_EQ(pieces, 2);
  for (int i = 0; i < 300; ++i) ASSERT_NO_THROW(integrator.step(st));
  for (const Vec3& x : st.x) ASSERT_TRUE(x.allFinite());
  std::cout << "[ figure ] a swinging bar cut through in " << cuts << " sweeps: energy change at a cut at most " << worst_rise
            << " of its kinetic + elastic energy; inertia added to hold the step " << added * 1e3 << " g (the bar: 40 g)\n";
}
