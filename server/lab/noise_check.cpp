#include "viscera/lab/noise_check.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <vector>

#include "viscera/lab/stress_controlled.hpp"

namespace viscera::lab {

double noise_level_measured(const TestData& t) {
  if (t.control == Control::stress) return noise_of_reading(t.strain);
  if (!t.stress_sd_pa.empty()) {
    double sq = 0;
    for (double x : t.stress_sd_pa) sq += x * x;
    return std::sqrt(sq / static_cast<double>(t.stress_sd_pa.size()));
  }
  return noise_of_reading(t.stress_pa);
}

double noise_level_pa(const TestData& t) { return noise_level_measured(t) * (t.control == Control::strain ? 1.0 : apparent_modulus_pa(t)); }

HoldNoise noise_in_holds(const TestData& t, double window_s) {
  const bool stress_control = t.control == Control::stress;
  const std::vector<double>& held = stress_control ? t.stress_pa : t.strain;
  const std::vector<double>& measured = stress_control ? t.strain : t.stress_pa;
  const std::size_t n = t.time_s.size();
  HoldNoise r;
  if (n < 27) return r;
  const auto [lo, hi] = std::minmax_element(held.begin(), held.end());
  const double tol = 4 * noise_from_second_differences(held) + 1e-6 * (*hi - *lo);
  // Residuals about the running mean, each divided by the share of the noise a w-sample mean
  // leaves in it (variance sd^2 (1 - 1/w) for white noise). The window is window_s in each
  // hold's own sampling (a logger may thin its rate in long holds), at least 9 samples.
  std::vector<double> residual;
  std::size_t start = 0;
  for (std::size_t k = 1; k <= n; ++k) {
    if (k < n && std::abs(held[k] - held[start]) <= tol) continue;
    const std::size_t end = k;  // held over [start, end)
    const double dt = end - start > 1 ? (t.time_s[end - 1] - t.time_s[start]) / static_cast<double>(end - 1 - start) : 0.0;
    const std::size_t half = dt > 0 ? std::max<std::size_t>(4, static_cast<std::size_t>(std::lround(0.5 * window_s / dt))) : 4;
    const std::size_t w = 2 * half + 1;
    if (dt > 0 && end - start >= 3 * w) {
      if (r.holds++ == 0) r.window_s = static_cast<double>(w) * dt;
      const double share = std::sqrt(1.0 - 1.0 / static_cast<double>(w));
      double sum = 0;
      const std::size_t first = start + w;  // the first window of the hold is left out
      for (std::size_t j = first - half; j <= first + half; ++j) sum += measured[j];
      for (std::size_t c = first; c + half < end; ++c) {
        residual.push_back(std::abs(measured[c] - sum / static_cast<double>(w)) / share);
        if (c + half + 1 < end) sum += measured[c + half + 1] - measured[c - half];
      }
    }
    start = k;
  }
  if (residual.empty()) return r;
  r.samples = residual.size();
  std::sort(residual.begin(), residual.end());
  if (const double median = residual[residual.size() / 2]; median > 0) {
    r.sd = median / 0.6745;
    return r;
  }
  // Quantised: most samples of a hold sit on one level, and the median residual says nothing.
  // The RMS of the central 98% then, never below the quantum's own noise (as the first estimate).
  const std::size_t kept = std::max<std::size_t>(1, residual.size() * 98 / 100);
  double sq = 0;
  for (std::size_t k = 0; k < kept; ++k) sq += residual[k] * residual[k];
  r.sd = std::max(std::sqrt(sq / static_cast<double>(kept)), quantum_of(measured) / std::sqrt(12.0));
  return r;
}

NoiseCheck check_noise(const Dataset& d) {
  NoiseCheck c;
  double first2 = 0, holds2 = 0;
  for (const auto& t : d.tests) {
    const HoldNoise h = noise_in_holds(t);
    if (h.holds == 0) continue;
    const double to_pa = t.control == Control::strain ? 1.0 : apparent_modulus_pa(t);
    if (c.tests++ == 0) c.window_s = h.window_s;
    c.holds += h.holds;
    c.first_stated = c.first_stated || (t.control == Control::strain && !t.stress_sd_pa.empty());
    first2 += noise_level_pa(t) * noise_level_pa(t);
    holds2 += h.sd * to_pa * h.sd * to_pa;
  }
  if (c.tests == 0) return c;
  c.first_pa = std::sqrt(first2 / c.tests);
  c.holds_pa = std::sqrt(holds2 / c.tests);
  c.agree = c.holds_pa <= kNoiseAgreementFactor * c.first_pa && c.first_pa <= kNoiseAgreementFactor * c.holds_pa;
  return c;
}

}  // namespace viscera::lab
