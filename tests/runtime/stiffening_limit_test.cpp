// The rule that refuses materials a deep press would break (server/runtime/stiffening_limit.hpp),  // SPDX-License-Identifier: Apache-2.0
// against its closed forms: the stiffness growth of each shape (gps/fung_map.hpp: g'(e) =
// exp(B e), 1 + B^2 e^2 / 2) at the 64-sub-step cap, and the edge map's compressive secant
// (1 - exp(-B e)) / (B e) at one half; and what its refusals say.
#include "viscera/runtime/stiffening_limit.hpp"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"

using namespace viscera::runtime;
using namespace viscera::tissue;

namespace {

constexpr double kStrain = 0.4;  // the scene's default largest_edge_strain
constexpr double kHeadroom = 1.1 * kStrain + 0.002;  // the integrator's, written out
constexpr double kCap = 64;

GpsMechanisms stiffening(GpsStiffening::Form form, StiffeningShape shape, double b = 1) {
  GpsMechanisms m;
  m.stiffening.b = b;
  m.stiffening.form = form;
  m.stiffening.shape = shape;
  return m;
}

std::string refusal(const GpsMechanisms& m, double allowed = kCap) {
  try {
    check_stiffening(m, kStrain, allowed, "organ.json");
  } catch (const viscera::common::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(StiffeningLimit, TheEnergyFormsLargestBIsWhereTheGrowthMeetsTheCap) {
  // exponential: the curvature g'(e) = exp(B e) is largest in tension; sqrt(exp(B e)) = 64.
  const double exponential = 2 * std::log(kCap) / kHeadroom;
  EXPECT_NEAR(largest_stiffening(stiffening(GpsStiffening::Form::energy, StiffeningShape::exponential), kStrain, kCap), exponential,
              2e-3 * exponential);
  EXPECT_NEAR(largest_stiffening(stiffening(GpsStiffening::Form::energy, StiffeningShape::odd_exponential), kStrain, kCap), exponential,
              2e-3 * exponential);
  // odd_polynomial: g'(e) = 1 + B^2 e^2 / 2 = 64^2.
  const double polynomial = std::sqrt(2 * (kCap * kCap - 1)) / kHeadroom;
  EXPECT_NEAR(largest_stiffening(stiffening(GpsStiffening::Form::energy, StiffeningShape::odd_polynomial), kStrain, kCap), polynomial,
              2e-3 * polynomial);
  // A tighter budget lowers it as the square of the allowed sub-steps.
  EXPECT_NEAR(largest_stiffening(stiffening(GpsStiffening::Form::energy, StiffeningShape::exponential), kStrain, 8), 2 * std::log(8.0) / kHeadroom,
              2e-3 * exponential);
}

TEST(StiffeningLimit, TheEdgeMapsLargestBIsWhereACompressedEdgeCarriesHalfTheLinearTension) {
  // (1 - exp(-x)) / x = 1/2 by Newton, from x = 1.
  double x = 1;
  for (int k = 0; k < 50; ++k) {
    const double f = (1 - std::exp(-x)) / x - 0.5, df = (std::exp(-x) * x - (1 - std::exp(-x))) / (x * x);
    x -= f / df;
  }
  EXPECT_NEAR(x, 1.5936, 1e-3);
  const double expected = x / kHeadroom;  // about 3.6: between the 3 that holds a 3 cm press and the 4 that collapses
  EXPECT_NEAR(largest_stiffening(stiffening(GpsStiffening::Form::edge_map, StiffeningShape::exponential), kStrain, kCap), expected, 2e-3 * expected);
}

TEST(StiffeningLimit, TheAllowedGrowthIsTheCapOrTheTicksBudget) {
  // dt 0.25 ms: 4 sub-steps a 1 ms tick at rest.
  EXPECT_DOUBLE_EQ(allowed_substep_growth(0.25e-3, 0, 1000, TickBudget{}), kCap);
  EXPECT_DOUBLE_EQ(allowed_substep_growth(0.25e-3, 0, 1000, TickBudget{0.1, 100}), 25.0);  // 100 sub-steps a tick
  EXPECT_DOUBLE_EQ(allowed_substep_growth(0.25e-3, 100e-6, 1000, TickBudget{10e-3, 10'000}), 25.0);  // 10 ms of 100 us sub-steps
  EXPECT_DOUBLE_EQ(ExplicitIntegrator::headroom_strain(kStrain), kHeadroom);
}

TEST(StiffeningLimit, RefusalsNameTheFieldTheGrowthAndTheLargestB) {
  EXPECT_EQ(refusal(stiffening(GpsStiffening::Form::energy, StiffeningShape::exponential, 18.5)), "");
  const std::string too_stiff = refusal(stiffening(GpsStiffening::Form::energy, StiffeningShape::exponential, 20));
  EXPECT_NE(too_stiff.find("organ.json"), std::string::npos) << too_stiff;
  EXPECT_NE(too_stiff.find("viscoelasticity.qlv_stiffening"), std::string::npos) << too_stiff;
  EXPECT_NE(too_stiff.find("organ.largest_edge_strain 0.4"), std::string::npos) << too_stiff;
  EXPECT_NE(too_stiff.find("needs 83.1 times the explicit sub-steps"), std::string::npos) << too_stiff;  // sqrt(exp(20 x 0.442))
  EXPECT_LT(too_stiff.size(), 400u) << "viscera-control shows 400 characters";
  EXPECT_NE(too_stiff.find("up to 18.8"), std::string::npos) << too_stiff;
  const std::string collapses = refusal(stiffening(GpsStiffening::Form::edge_map, StiffeningShape::exponential, 4));
  EXPECT_NE(collapses.find("edge-map form"), std::string::npos) << collapses;
  EXPECT_LT(collapses.size(), 400u) << collapses;
  EXPECT_NE(collapses.find("up to 3.6"), std::string::npos) << collapses;
  // The asymmetry alone: compressed edges r times as stiff as stretched ones, against the slope at
  // rest, where the asymmetry's blend is halfway: r / ((1 + sqrt(r)) / 2)^2 = 3.8 at r = 1000.
  GpsMechanisms asymmetric;
  asymmetric.stiffening.form = GpsStiffening::Form::energy;
  asymmetric.asymmetry.compression_ratio = 1000;
  EXPECT_EQ(refusal(asymmetric), "");
  EXPECT_EQ(refusal(asymmetric, 2.0), "");
  const std::string ratio = refusal(asymmetric, 1.9);
  EXPECT_NE(ratio.find("viscoelasticity.compression_ratio"), std::string::npos) << ratio;
  EXPECT_EQ(refusal(GpsMechanisms{}), "");  // no stiffening: nothing to refuse
}

}  // namespace
