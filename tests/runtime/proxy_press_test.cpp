// The contact proxy on the bundled livers, as the server steps them (the scene's organ, 1 ms  // SPDX-License-Identifier: Apache-2.0
// ticks, no DDS), side by side with the penalty contact: a probe commanded 60 mm below the top at
// 1 cm/s, and a slide at 8 mm depth at 2 cm/s. Measured: the force's largest fall below its
// running peak, the proxy's point off the deformed surface (brute force over every triangle, with
// a ray's parity for inside: another code path), physics resets, and the largest 1 ms change of
// the force during the slide against its mean.
// DISABLED: the proxy misses both targets of its issue on the liver today, and these are the
// measurements that say by how much (docs/HAPTICS.md, "The contact proxy"); run them with
// --gtest_also_run_disabled_tests. On the 1.5k liver: pressed 60 mm the force falls 35% below its
// running peak (the penalty contact 41%), with the proxy's point within 0.2 mm of the surface and
// no reset; slid at 8 mm depth the largest 1 ms change is 7.2% of the mean force (the penalty
// contact 1.5%).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "viscera/runtime/command_responder.hpp"
#include "viscera/runtime/contact_proxy.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/surface_exit.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

namespace viscera::runtime {
namespace {

using tissue::BoundaryConditions;

/// Signed distance of `c` from the surface: positive outside, negative inside.
double signed_distance(const ContactSurface& s, std::span<const Vec3> x, const Vec3& c) {
  double nearest = INFINITY;
  for (const auto& t : s.triangles) {
    Vec3 w;
    nearest = std::min(nearest, (c - closest_point_on_triangle(c, x[t[0]], x[t[1]], x[t[2]], &w)).norm());
  }
  return inside_surface(s, x, c) ? -nearest : nearest;
}

struct Outcome {
  double peak_n = 0, worst_fall = 0, worst_off_surface_m = 0, slide_mean_n = 0, slide_largest_step_n = 0;
  int resets = 0;
};

/// The probe (6 mm tip) from 2 mm above the top centre straight down at 1 cm/s until `depth_m`
/// below the first contact, held 0.2 s; or, with `slide`, pressed 8 mm and then moved 4 cm along x
/// at 2 cm/s.
Outcome run(const std::string& scene_file, bool proxy, double depth_m, bool slide) {
  SceneSpec spec = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_file);
  spec.contact_force_limit_n = 10;  // the device clamp
  const auto organ = build_organ(spec, TickBudget{1e9});
  InstrumentSpec tip;
  tip.tip_radius_m = 0.006;
  ContactProxy contact_proxy(organ->contact_surface, proxy_parameters(spec, tip));
  const ProbeContact penalty(organ->contact_surface, tip.tip_radius_m, spec.contact_stiffness_n_per_m, 0.02, spec.contact_damping_s_per_m);
  const tissue::Box& b = organ->bounds;
  Vec3 goal(0.5 * (b.lo.x() + b.hi.x()) - (slide ? 0.02 : 0.0), 0.5 * (b.lo.y() + b.hi.y()), b.hi.z() + 0.002), velocity = Vec3::Zero();
  ContactResult last;
  organ->integrator->boundary_conditions().force_field = [&](const BoundaryConditions::FieldEvaluation& e) {
    last = proxy ? contact_proxy.apply(goal, velocity, e) : penalty.apply(goal, velocity, e);
  };
  tissue::State state = tissue::State::at_rest(*organ->mesh);
  Outcome o;
  double contact_z = NAN;
  Vec3 previous_force = Vec3::Zero();
  const auto tick = [&](const Vec3& next) {
    velocity = (next - goal) / 1e-3;
    goal = next;
    if (proxy) contact_proxy.track(goal, state.x, 1e-3);
    try {
      organ->integrator->advance(state, 1e-3);
    } catch (const tissue::SimulationError&) {
      ++o.resets;
      state = tissue::State::at_rest(*organ->mesh);
      contact_proxy.release();
    }
    if (std::isnan(contact_z) && last.in_contact) contact_z = goal.z();
  };
  const double press = slide ? 0.008 : depth_m;
  for (int held = 0; held < 200;) {
    const double target = std::isnan(contact_z) ? b.lo.z() : contact_z - press;
    const double move = std::max(-1e-5, target - goal.z());
    tick(goal + Vec3(0, 0, move));
    held += move == 0.0;
    if (std::isnan(contact_z) || contact_z - goal.z() < 1e-3) continue;
    const double f = last.force_on_tool.norm();
    o.peak_n = std::max(o.peak_n, f);
    if (!slide) o.worst_fall = std::max(o.worst_fall, (o.peak_n - f) / o.peak_n);
    if (proxy && contact_proxy.anchored() && !slide)
      o.worst_off_surface_m = std::max(o.worst_off_surface_m, std::abs(signed_distance(*organ->contact_surface, state.x, last.point)));
  }
  if (slide) {
    previous_force = last.force_on_tool;
    for (int t = 0; t < 2000; ++t) {
      tick(goal + Vec3(2e-5, 0, 0));
      o.slide_mean_n += last.force_on_tool.norm() / 2000;
      o.slide_largest_step_n = std::max(o.slide_largest_step_n, (last.force_on_tool - previous_force).norm());
      previous_force = last.force_on_tool;
    }
  }
  return o;
}

TEST(ProxyPress, DISABLED_TheLiverPressed60mmHoldsTheProxyOnItsSurfaceAndTheForceNeverFallsBack) {
  for (const bool proxy : {false, true}) {
    const Outcome o = run("liver.json", proxy, 0.06, false);
    std::printf(
        "[ figure ] liver.json pressed 60 mm at 1 cm/s, %s contact: peak %.3f N, largest fall below the running peak %.1f%%, "
        "%d physics resets, proxy's point off the surface at most %.3f mm\n",
        proxy ? "proxy" : "penalty", o.peak_n, 100 * o.worst_fall, o.resets, 1e3 * o.worst_off_surface_m);
    if (!proxy) continue;
    EXPECT_EQ(o.resets, 0);
    EXPECT_LT(o.worst_fall, 0.10);
    EXPECT_LT(o.worst_off_surface_m, 0.5e-3);
  }
}

TEST(ProxyPress, DISABLED_ASlideAt8mmDepthChangesTheForceSmoothly) {
  for (const bool proxy : {false, true}) {
    const Outcome o = run("liver.json", proxy, 0.0, true);
    std::printf(
        "[ figure ] liver.json slid 4 cm at 8 mm depth at 2 cm/s, %s contact: mean force %.3f N, largest 1 ms change %.2f%% of it, "
        "%d physics resets\n",
        proxy ? "proxy" : "penalty", o.slide_mean_n, 100 * o.slide_largest_step_n / o.slide_mean_n, o.resets);
    if (!proxy) continue;
    EXPECT_EQ(o.resets, 0);
    EXPECT_LT(o.slide_largest_step_n, 0.02 * o.slide_mean_n);
  }
}

}  // namespace
}  // namespace viscera::runtime
