// The palpating search (tools/haptic-client/palpating_device.hpp) against a simple organ it was not
// built on: a flat-topped slab whose indentation stiffness is k0 everywhere and (1 + A) k0 over a
// hidden lump, falling off as a Gaussian of the distance from it (a lump felt through the tissue
// above it), plus a slow trend across the organ (thicker on one side). The device is driven at
// 1 kHz with the force this model gives; it must mark within 1 cm of the lump, wherever the lump
// lies (lumps drawn at random, 20 places), and never press harder than its safe force by much.
#include "palpating_device.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace {
using viscera::protocol::Vector3;

struct SlabOrgan {
  double top_z = 0.04;  // [m]
  double k0 = 60;  // indentation stiffness away from the lump [N/m]
  double lump_gain = 1.0;  // (1 + A) k0 right over the lump
  double lump_x = 0, lump_y = 0, lump_sigma = 0.012;  // [m]
  double trend_per_m = 3.0;  // k grows by this fraction per metre of x (the organ thicker on one side)
  double stiffness(double x, double y) const {
    const double r2 = (x - lump_x) * (x - lump_x) + (y - lump_y) * (y - lump_y);
    return k0 * (1 + trend_per_m * x) * (1 + lump_gain * std::exp(-r2 / (2 * lump_sigma * lump_sigma)));
  }
  /// Force on the tip (up, out of the tissue) and whether it touches.
  std::pair<Vector3, bool> force(const Vector3& tip) const {
    const double depth = top_z - tip[2];
    if (depth <= 0) return {{0, 0, 0}, false};
    return {{0, 0, stiffness(tip[0], tip[1]) * depth}, true};
  }
};

viscera::protocol::Scene scene() {
  viscera::protocol::Scene s;
  s.name = "slab";
  s.bounds_min = {-0.09, -0.05, 0.0};
  s.bounds_max = {0.09, 0.05, 0.04};
  return s;
}

struct Outcome {
  bool marked = false;
  double x = 0, y = 0, peak_force_n = 0;
};

Outcome palpate(const SlabOrgan& organ) {
  viscera::haptic::PalpatingDevice device(scene(), 0.006, false);
  Outcome out;
  for (double t = 0; t < 120; t += 1e-3) {
    const auto s = device.read(t);
    if (s.buttons & 1u) {
      out.marked = true;
      out.x = s.tip_m[0];
      out.y = s.tip_m[1];
    }
    const auto [f, touching] = organ.force(s.tip_m);
    out.peak_force_n = std::max(out.peak_force_n, f[2]);
    device.render(f, touching);
    if (s.finished) break;
  }
  return out;
}
}  // namespace

TEST(PalpatingDevice, MarksAHiddenLumpWithin1CmWhereverItLies) {
  std::mt19937 rng(20261126);
  // Lumps anywhere the search presses (it keeps 15% of the organ clear at its sides).
  std::uniform_real_distribution<double> x(-0.06, 0.06), y(-0.03, 0.03);
  int found = 0;
  for (int k = 0; k < 20; ++k) {
    SlabOrgan organ;
    organ.lump_x = x(rng);
    organ.lump_y = y(rng);
    const Outcome o = palpate(organ);
    ASSERT_TRUE(o.marked) << "lump " << k;
    const double miss = std::hypot(o.x - organ.lump_x, o.y - organ.lump_y);
    found += miss <= 0.01;
    EXPECT_LE(miss, 0.01) << "lump at (" << organ.lump_x << ", " << organ.lump_y << ") m marked at (" << o.x << ", " << o.y << ") m";
    EXPECT_LE(o.peak_force_n, 2.5) << "pressed harder than its safe force";
  }
  std::printf("palpating search on the slab: %d of 20 lumps marked within 1 cm\n", found);
}

TEST(PalpatingDevice, MarksNothingWhereThereIsNoTissue) {
  SlabOrgan organ;
  organ.top_z = -1.0;  // below the scene's bounds: the probe never touches
  const Outcome o = palpate(organ);
  EXPECT_FALSE(o.marked);
}
