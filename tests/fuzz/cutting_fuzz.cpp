// libFuzzer target for cutting (docs/CUTTING.md): the bytes are a sequence of blade sweeps through
// a 4 x 3 x 3 cm box of 216 tetrahedra. Blade ends are quantised to a quarter of the mesh spacing,
// so sweeps go exactly through nodes, along edges and in the planes of faces, where a cutter's
// arithmetic is weakest. After every sweep: the mesh is valid (positive volumes, no degenerate or
// repeated tetrahedron, no unused node) and conforming (no face shared by three), the rest volume
// and the lumped mass are the box's, new nodes sit on their edges; for one input in sixteen, the GPS
// forces of the cut organ, stretched, are finite (calibrating every element is what costs). Any
// violation aborts. At exit it prints the number of sweeps applied (run_fuzz.sh requires 10,000).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/mesh_validation.hpp"

using namespace viscera::tissue;

namespace {

constexpr double kSpacing = 0.01;

std::size_t sweeps = 0;

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
  static const bool report = [] { return std::atexit([] { std::printf("cutting_fuzz: %zu sweeps applied\n", sweeps); }) == 0; }();
  (void)report;
  TetMesh m = box;
  MeshCutter cutter(m, CutOptions{size > 0 ? 0.05 * (1 + data[0] % 7) : 0.2});  // snap fractions 0.05 to 0.35
  std::vector<Vec3> x = m.nodes;
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
  // The cut organ still computes: finite forces when stretched.
  if (size == 0 || data[0] % 16 != 0 || m.tets.size() == box.tets.size()) return 0;
  const auto mesh = std::make_shared<TetMesh>(m);
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.3;
  const GpsModel gps(mesh, {elasticity_matrix(IsotropicElasticity{5e3, 0.45})}, {}, o);
  for (auto& p : x) p.x() *= 1.1;
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  gps.add_forces(x, f);
  for (const Vec3& fi : f) require(fi.allFinite(), "a force is not finite");
  return 0;
}
