// libFuzzer target for cutting (docs/CUTTING.md): the bytes are a sequence of blade sweeps through  // SPDX-License-Identifier: Apache-2.0
// a 4 x 3 x 3 cm box of 216 tetrahedra. Blade ends are quantised to a quarter of the mesh spacing,
// so sweeps go exactly through nodes, along edges and in the planes of faces, where a cutter's
// arithmetic is weakest. After every sweep: the mesh is valid (positive volumes, no degenerate or
// repeated tetrahedron, no unused node) and conforming (no face shared by three), the rest volume
// and the lumped mass are the box's, new nodes sit on their edges. For one input in 64 the
// organ also runs while it is cut (calibrating and factorising is what costs): a viscoelastic GPS,
// the explicit and the implicit (CHOLMOD) integrator, the box held at its bottom under gravity, all
// three following every sweep in place; the implicit masses keep the box's mass, and at the end a
// few steps of each are finite, as are the forces of the cut organ stretched. Any violation aborts.
// At exit it prints the number of sweeps applied (run_fuzz.sh requires 10,000).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/mesh_validation.hpp"

using namespace viscera::tissue;

namespace {

constexpr double kSpacing = 0.01;

std::size_t sweeps = 0, followed = 0;  // all sweeps applied; those the running organ followed

void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "cutting_fuzz: %s\n", what);
  std::abort();
}

Vec3 point(const std::uint8_t* b) {
  // 0..255 -> -1 cm .. 5.375 cm in quarter-centimetre steps (the box is 4 x 3 x 3 cm).
  const auto q = [](std::uint8_t v) { return (static_cast<double>(v % 26) - 4.0) * 0.25 * kSpacing; };
  return {q(b[0]), q(b[1]), q(b[2])};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const TetMesh box = make_box_mesh(Vec3(0, 0, 0), Vec3(0.04, 0.03, 0.03), 4, 3, 3);
  static const double volume0 = mesh_volume(box);
  static const bool report = [] {
    return std::atexit([] {
             std::printf("cutting_fuzz: %zu sweeps applied, %zu changes of the mesh followed by the model and both integrators\n", sweeps, followed);
           }) == 0;
  }();
  (void)report;
  const auto mesh = std::make_shared<TetMesh>(box);
  TetMesh& m = *mesh;
  MeshCutter cutter(m, CutOptions{size > 0 ? 0.05 * (1 + data[0] % 7) : 0.2});  // snap fractions 0.05 to 0.35
  std::vector<Vec3> x = m.nodes;
  // The running organ, for one input in 64: model, integrators and their states.
  std::unique_ptr<GpsModel> gps;
  std::unique_ptr<ExplicitIntegrator> explicit_path;
  std::unique_ptr<ImplicitIntegrator> implicit_path;
  State explicit_state, implicit_state;
  std::vector<double> memory;
  if (size > 0 && data[0] % 64 == 0) {
    GpsOptions o;
    o.variant = GpsVariant::energy_consistent;
    o.volume_stiffness_fraction = 0.3;
    o.mechanisms.viscous.omega_rad_s = {2.0, 200.0};
    o.mechanisms.viscous.shear_weight = {0.2, 0.2};
    o.mechanisms.viscous.bulk_weight = {0.0, 0.0};
    gps = std::make_unique<GpsModel>(mesh, std::vector<Mat6>{elasticity_matrix(IsotropicElasticity{5e3, 0.45})}, std::vector<std::uint16_t>{}, o);
    BoundaryConditions bc;
    bc.gravity_m_s2 = Vec3(0, 0, -9.81);
    bc.fixed_nodes = nodes_in_box(m, Box{Vec3(-1, -1, -1), Vec3(1, 1, 1e-9)});
    const std::vector<double> rho(m.tet_count(), 1000.0);
    explicit_path = std::make_unique<ExplicitIntegrator>(*gps, rho, bc);
    ImplicitOptions io;
    io.dt_s = 1e-3;
    implicit_path = std::make_unique<ImplicitIntegrator>(*gps, rho, bc, io);
    explicit_state = State::at_rest(m);
    explicit_state.memory.assign(gps->memory_size(), 0.0);
    explicit_path->step(explicit_state);  // moving, its memory in use
    implicit_state = State::at_rest(m);
  }
  // A sweep: a byte (stroke id in bits 0-1; bit 2: the blade goes on from where the last sweep
  // left it), the blade's two ends (3 bytes each) and its move in this tick (3 bytes, -2 to +2
  // quarter-centimetres per axis).
  constexpr std::size_t kSweep = 10;
  BladeSweep sweep{};
  bool first = true;
  for (std::size_t at = 1; at + kSweep <= size && at < 1 + 32 * kSweep; at += kSweep) {
    if (first || (data[at] & 4) == 0) {
      sweep.a0 = point(data + at + 1);
      sweep.b0 = point(data + at + 4);
    } else {
      sweep.a0 = sweep.a1;
      sweep.b0 = sweep.b1;
    }
    first = false;
    const Vec3 move = Vec3(data[at + 7] % 5 - 2.0, data[at + 8] % 5 - 2.0, data[at + 9] % 5 - 2.0) * 0.25 * kSpacing;
    sweep.a1 = sweep.a0 + move;
    sweep.b1 = sweep.b0 + move;
    const CutChange c = cutter.cut(sweep, x, data[at] % 4);
    ++sweeps;
    require(c.origin.size() == m.tets.size() && c.first_new_node + c.new_nodes.size() == m.nodes.size(), "change does not match the mesh");
    extend_nodal(c, x);
    for (std::size_t i = c.first_new_node; i < x.size(); ++i) require((x[i] - m.nodes[i]).norm() < 1e-15, "a new node is off its edge");
    if (!c.topology_changed()) continue;
    if (gps) {
      ++followed;
      gps->follow_edit(c.edit(), explicit_state.memory);
      explicit_path->follow_edit(c.edit(), explicit_state);
      implicit_path->follow_edit(c.edit(), implicit_state);
      double implicit_mass = 0;
      for (const double mi : implicit_path->masses()) implicit_mass += mi;
      require(std::fabs(implicit_mass - 1000.0 * volume0) <= 1e-12 * 1000.0 * volume0, "the implicit integrator's mass changed");
      for (const Vec3& p : explicit_state.x) require(p.allFinite(), "a position followed into the cut is not finite");
    }
    try {
      validate_mesh(m);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      require(false, "the cut mesh is not valid");
    }
    require(overshared_faces(m) == 0, "a face is shared by three tetrahedra");
    require(std::fabs(mesh_volume(m) - volume0) <= 1e-12 * volume0, "volume changed");
    double mass = 0;
    for (const double mi : lumped_masses(m, 1000.0)) mass += mi;
    require(std::fabs(mass - 1000.0 * volume0) <= 1e-12 * 1000.0 * volume0, "mass changed");
  }
  if (!gps || m.tets.size() == box.tets.size()) return 0;
  // The cut organ runs on: explicit steps (memory carried into the children) and backward Euler
  // steps on the pattern analysed when the cuts were followed; then its forces, stretched.
  try {
    for (int k = 0; k < 5; ++k) explicit_path->step(explicit_state);
    implicit_path->step(implicit_state);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    require(false, "the cut organ does not step");
  }
  for (const Vec3& p : explicit_state.x) require(p.allFinite(), "an explicit position is not finite");
  for (const Vec3& p : implicit_state.x) require(p.allFinite(), "an implicit position is not finite");
  for (auto& p : x) p.x() *= 1.1;
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  gps->add_forces(x, f);
  for (const Vec3& fi : f) require(fi.allFinite(), "a force is not finite");
  return 0;
}
