#include "viscera/lab/parameter_uncertainty.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "viscera/lab/fit.hpp"

namespace viscera::lab {

std::vector<ParameterEstimate> parameters_of(const MaterialModel& m) {
  std::vector<ParameterEstimate> out{{"E", "Pa", m.modulus_pa}, {"eta", "Pa s", m.viscosity_pa_s}};
  if (m.has(Mechanism::strain_stiffening)) out.push_back({"B", "-", m.stiffening_b});
  if (m.has(Mechanism::tension_compression_asymmetry)) out.push_back({"r", "-", m.compression_ratio});
  if (m.has(Mechanism::first_load_softening)) out.push_back({"d", "-", m.softening_d});
  if (m.has(Mechanism::first_load_softening) && m.history_carried) out.push_back({"k (kept between tests)", "-", m.softening_kept});
  if (m.has(Mechanism::broadband_relaxation))
    for (std::size_t l = 0; l < m.relaxation_time_s.size(); ++l) {
      char name[64];
      std::snprintf(name, sizeof name, "E_l (tau %.3g s)", m.relaxation_time_s[l]);
      out.push_back({name, "Pa", l < m.relaxation_modulus_pa.size() ? m.relaxation_modulus_pa[l] : 0.0});
    }
  return out;
}

ParameterUncertainty bootstrap_over_tests(const MaterialModel& fitted, const Dataset& d, int replicates, unsigned seed) {
  ParameterUncertainty u;
  u.parameters = parameters_of(fitted);
  const std::size_t n = d.tests.size();
  u.method = "bootstrap over tests: " + std::to_string(n) + " tests drawn with replacement, the model's structure fitted again to each draw; " +
             "standard error = SD over the draws, interval = their 2.5% and 97.5% quantiles";
  if (n < 3) {
    u.not_run = std::to_string(n) + (n == 1 ? " test" : " tests") + ": a bootstrap over tests needs at least 3";
    return u;
  }
  if (replicates < 2) {
    u.not_run = "turned off";
    return u;
  }
  std::mt19937_64 rng(0xb0075ull + seed);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::vector<std::vector<double>> draws(u.parameters.size());
  for (int b = 0; b < replicates; ++b) {
    std::vector<const TestData*> tests;
    bool strain_controlled = false;
    while (!strain_controlled) {  // the nonlinear parameters are searched on strain-controlled tests
      tests.clear();
      for (std::size_t k = 0; k < n; ++k) {
        tests.push_back(&d.tests[pick(rng)]);
        strain_controlled = strain_controlled || tests.back()->control == Control::strain;
      }
    }
    const MaterialModel refit = fit_model(fitted, tests);
    const bool same_form = !fitted.has(Mechanism::strain_stiffening) || refit.stiffening_form == fitted.stiffening_form;
    u.same_form += same_form;
    const std::vector<ParameterEstimate> p = parameters_of(refit);
    for (std::size_t k = 0; k < p.size() && k < draws.size(); ++k)
      if (p[k].name != "B" || same_form) draws[k].push_back(p[k].value);
  }
  u.replicates = replicates;
  for (std::size_t k = 0; k < u.parameters.size(); ++k) {
    std::vector<double>& x = draws[k];
    ParameterEstimate& e = u.parameters[k];
    if (x.size() < 2) {  // B, where the draws chose other forms
      e.determined = false;
      continue;
    }
    double mean = 0, sq = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    for (double v : x) sq += (v - mean) * (v - mean);
    e.standard_error = std::sqrt(sq / static_cast<double>(x.size() - 1));
    std::sort(x.begin(), x.end());
    const auto quantile = [&](double q) {
      const double at = q * static_cast<double>(x.size() - 1);
      const auto lo = static_cast<std::size_t>(std::floor(at));
      const std::size_t hi = std::min(lo + 1, x.size() - 1);
      return x[lo] + (at - static_cast<double>(lo)) * (x[hi] - x[lo]);
    };
    e.low = quantile(0.025);
    e.high = quantile(0.975);
    // A modulus or a viscosity the draws can take to zero is not determined either: the data allow
    // the model without it.
    const bool can_vanish = e.value > 0 && e.low <= 0 && e.unit != "-";
    e.determined = e.standard_error <= kUndeterminedShare * std::abs(e.value) && !can_vanish;
  }
  return u;
}

}  // namespace viscera::lab
