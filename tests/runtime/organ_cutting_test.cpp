// A scalpel's cut through the server's organ (organ_cutting.hpp): the bundled liver scene cut by a
// blade drawn through its top, as the server does it tick by tick. Checked against conservation
// (rest volume, mass), the boundary extracted from the whole cut mesh, and rest: an organ cut at
// rest has the cut mesh as its rest shape, so it stays where it is, on the scene's own integrator.
#include "viscera/runtime/organ_cutting.hpp"

#include <algorithm>
#include <iostream>
#include <numeric>

#include <gtest/gtest.h>

#include "viscera/runtime/organ.hpp"
#include "viscera/tissue/mesh/mesh_validation.hpp"

namespace viscera::runtime {
namespace {

using namespace viscera::tissue;

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

struct Cut {
  std::unique_ptr<Organ> organ;
  State state;
  double volume_before = 0, mass_before = 0;
  std::size_t sweeps = 0, changed = 0;
};

/// The scene's organ cut at rest by its 2 cm blade, upright, its tip `depth_m` below the top of
/// the organ's box, drawn 6 cm along x through the middle in `ticks` sweeps.
Cut cut_liver(const std::string& scene_file, double depth_m, int ticks, double dy_m = 0) {
  Cut c;
  SceneSpec scene = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_file);
  c.organ = build_organ(scene);
  Organ& o = *c.organ;
  c.state = State::at_rest(*o.mesh);
  c.volume_before = mesh_volume(*o.mesh);
  c.mass_before = total(o.integrator->masses());
  const Vec3 mid = 0.5 * (o.bounds.lo + o.bounds.hi) + Vec3(0, dy_m, 0);
  const double z = o.bounds.hi.z() - depth_m, blade = 0.02;
  for (int k = 0; k < ticks; ++k) {
    const double x0 = mid.x() - 0.03 + 0.06 * k / ticks, x1 = mid.x() - 0.03 + 0.06 * (k + 1) / ticks;
    const BladeSweep sweep{Vec3(x0, mid.y(), z), Vec3(x0, mid.y(), z + blade), Vec3(x1, mid.y(), z), Vec3(x1, mid.y(), z + blade)};
    const SweepOutcome out = cut_organ(o, sweep, c.state, 0);
    ++c.sweeps;
    c.changed += out.topology_changed;
  }
  return c;
}

TEST(OrganCutting, AnIncisionKeepsVolumeAndMassAndTheCutOrganStaysAtRest) {
  Cut c = cut_liver("liver.json", 0.018, 300);
  Organ& o = *c.organ;
  ASSERT_TRUE(can_cut(o));
  ASSERT_GT(c.changed, 5u);
  ASSERT_NO_THROW(validate_mesh(*o.mesh));
  EXPECT_EQ(overshared_faces(*o.mesh), 0u);
  EXPECT_NEAR(mesh_volume(*o.mesh), c.volume_before, 1e-9 * c.volume_before);
  const double mass = total(o.integrator->masses());
  EXPECT_GE(mass, c.mass_before * (1 - 1e-12));  // inertia may be added to hold the step, never lost
  // The boundary brought along equals the one extracted from the whole cut mesh.
  const BoundarySurface whole = extract_boundary(*o.mesh);
  EXPECT_EQ(o.boundary.triangles.size(), whole.triangles.size());
  EXPECT_EQ(o.boundary.nodes, whole.nodes);
  EXPECT_GT(o.topology_generation, 0u);
  // At rest, cut at rest: it stays at rest, step after step (a new element too stiff for the step
  // would ring up from rounding within a few hundred steps).
  State s = c.state;
  for (int k = 0; k < 3000; ++k) ASSERT_NO_THROW(o.integrator->step(s)) << "step " << k;
  double moved = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i) moved = std::max(moved, (s.x[i] - o.mesh->nodes[i]).norm());
  EXPECT_LT(moved, 1e-9);
  std::cout << "[ figure ] liver incision at rest: " << c.sweeps << " sweeps, " << c.changed << " changed the mesh, " << o.mesh->tet_count()
            << " tets, surface generation " << o.topology_generation << ", inertia added " << 1e3 * (mass - c.mass_before)
            << " g; largest drift after 3000 steps " << moved << " m\n";
}

TEST(OrganCutting, IncisionsAtManyDepthsAndPlacesLeaveTheOrganStableAtItsStep) {
  // The scene's step is the organ's global critical step (its worst elements' own steps lie below
  // it): a cut must not raise the organ's highest frequency above what the step allows.
  int cases = 0;
  for (const double depth : {0.006, 0.010, 0.014, 0.018, 0.022, 0.026})
    for (const double dy : {-0.02, -0.01, 0.0, 0.01, 0.02}) {
      Cut c = cut_liver("liver.json", depth, 400, dy);
      State s = c.state;
      for (int k = 0; k < 2000; ++k) ASSERT_NO_THROW(c.organ->integrator->step(s)) << "depth " << depth << " dy " << dy << " step " << k;
      ++cases;
    }
  EXPECT_EQ(cases, 30);
}

}  // namespace
}  // namespace viscera::runtime
