// A specimen remembers its tests (test_history.hpp): which tests share a specimen, what each  // SPDX-License-Identifier: Apache-2.0
// starts from, and a softened specimen's response against the closed form of the softening law.
#include "viscera/lab/test_history.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/lab/material_model.hpp"
#include "viscera/lab/stress_controlled.hpp"

using namespace viscera::lab;

namespace {

// A test sampled every 10 ms along straight pieces through the knots (t, value).
TestData along(const char* file, Control control, const std::vector<std::pair<double, double>>& knots) {
  TestData t;
  t.file = file;
  t.control = control;
  for (std::size_t k = 1; k < knots.size(); ++k)
    for (double x = knots[k - 1].first; x < knots[k].first - 1e-9; x += 0.01) {
      const double f = (x - knots[k - 1].first) / (knots[k].first - knots[k - 1].first);
      t.time_s.push_back(x);
      (control == Control::strain ? t.strain : t.stress_pa).push_back(knots[k - 1].second + f * (knots[k].second - knots[k - 1].second));
    }
  (control == Control::strain ? t.stress_pa : t.strain).assign(t.time_s.size(), 0.0);
  return t;
}

}  // namespace

TEST(TestHistory, EachTestStartsWhereTheTestsBeforeItOnItsSpecimenLeftIt) {
  Dataset d;
  d.tests = {along("a", Control::strain, {{0, 0}, {1, 0.10}, {2, 0}}), along("b", Control::strain, {{0, 0}, {1, -0.05}, {2, 0}}),
             along("c", Control::strain, {{0, 0}, {1, 0.20}, {2, 0}}), along("d", Control::strain, {{0, 0}, {1, 0.03}, {2, 0}})};
  d.tests[2].specimen = Specimen{0.01, 0.01, 0.003, 1000};  // another specimen: starts untouched, leaves the data set's alone
  carry_history(d);
  const double expect[4][2] = {{0, 0}, {0.10, 0}, {0, 0}, {0.10, 0.05}};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(d.tests[k].before_tension, expect[k][0], 1e-12) << d.tests[k].file;
    EXPECT_NEAR(d.tests[k].before_compression, expect[k][1], 1e-12) << d.tests[k].file;
  }
  d.history = History::reset;
  carry_history(d);
  for (const auto& t : d.tests) EXPECT_EQ(t.before_tension + t.before_compression, 0.0) << t.file;
}

// Softening law (material_model.hpp): below the largest strain m seen, s = (1 - d (1 - |e|/m)) e.
TEST(TestHistory, ASoftenedSpecimenReloadsOnTheSofterCurveUnderStrainAndUnderStress) {
  MaterialModel m;
  m.mechanisms = 1u << static_cast<unsigned>(Mechanism::first_load_softening);
  m.softening_d = 0.4;
  m.modulus_pa = 1000.0;
  m.viscosity_pa_s = 0.0;
  const double peak = 0.1;
  // Strain control: to 0.15, past the earlier peak; the stress follows the softer curve, then the virgin one.
  TestData reload = along("reload", Control::strain, {{0, 0}, {1.5, 0.15}});
  reload.before_tension = peak;
  const std::vector<double> y = predict_stress(m, reload);
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double e = reload.strain[k];
    const double expect = e < peak ? m.modulus_pa * e * (1 - m.softening_d * (1 - e / peak)) : m.modulus_pa * e;
    EXPECT_NEAR(y[k], expect, 1e-9 * m.modulus_pa) << "strain " << e;
  }
  // The same test on an untouched specimen: the virgin curve throughout.
  reload.before_tension = 0.0;
  const std::vector<double> virgin = predict_stress(m, reload);
  for (std::size_t k = 0; k < y.size(); ++k) EXPECT_NEAR(virgin[k], m.modulus_pa * reload.strain[k], 1e-9 * m.modulus_pa);
  // Stress control: 50 Pa held; with tau = eta / E = 1 ms the strain settles on the softer curve,
  // where E e (1 - d + d e / m) = sigma: a quadratic.
  m.viscosity_pa_s = 1.0;
  TestData creep = along("creep", Control::stress, {{0, 0}, {0.1, 50.0}, {2.0, 50.0}});
  creep.before_tension = peak;
  const double a = m.softening_d / peak, b = 1 - m.softening_d, c = -50.0 / m.modulus_pa;
  const double settled = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  ASSERT_LT(settled, peak);
  EXPECT_NEAR(predict_measured(m, creep).back(), settled, 1e-6 * settled);
  creep.before_tension = 0.0;
  EXPECT_NEAR(predict_measured(m, creep).back(), 50.0 / m.modulus_pa, 1e-6 * settled);
}
