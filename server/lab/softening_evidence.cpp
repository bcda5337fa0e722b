#include "viscera/lab/softening_evidence.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

namespace viscera::lab {

SofteningEvidence softening_evidence(const MaterialModel& model, const Dataset& d, double noise_pa, bool across_tests) {
  constexpr int kBins = 10;
  double max_strain = 0;
  for (const auto& t : d.tests)
    for (double e : t.strain) max_strain = std::max(max_strain, std::abs(e));
  SofteningEvidence ev;
  ev.across_tests = across_tests;
  double diff = 0.0, var = 0.0;
  double sum_v[kBins] = {}, sum_b[kBins] = {};
  long n_v[kBins] = {}, n_b[kBins] = {};
  const auto compare_bins = [&] {
    for (int b = 0; b < kBins; ++b) {
      if (n_v[b] > 0 && n_b[b] > 0) {
        diff += sum_v[b] / static_cast<double>(n_v[b]) - sum_b[b] / static_cast<double>(n_b[b]);
        var += noise_pa * noise_pa * (1.0 / static_cast<double>(n_v[b]) + 1.0 / static_cast<double>(n_b[b]));
        ++ev.bins;
        ev.virgin += n_v[b];
        ev.below_peak += n_b[b];
      }
      sum_v[b] = sum_b[b] = 0;
      n_v[b] = n_b[b] = 0;
    }
  };
  // Within each test, each starting untouched (the same rates, the same protocol); or across the
  // tests, each starting where the ones before it left its specimen: first loading is then mostly
  // in one test and reloading in the next ones, so the bins gather every test's samples.
  for (const auto& t : d.tests) {
    if (t.control != Control::strain) continue;
    const auto y = predict_stress(model, t);
    double peak_t = across_tests ? t.before_tension : 0.0, peak_c = across_tests ? t.before_compression : 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      const double e = t.strain[k], a = std::abs(e), r = (t.stress_pa[k] - y[k]) * (e >= 0 ? 1 : -1);
      const double peak = e >= 0 ? peak_t : peak_c;
      const int bin = static_cast<int>((a / max_strain - 0.2) / 0.8 * kBins);
      // Loading only (|strain| growing), so that both kinds move the same way at the same rate.
      const bool loading = k > 0 && a > std::abs(t.strain[k - 1]) && e * t.strain[k - 1] >= 0;
      if (bin >= 0 && bin < kBins && loading) {
        if (a >= peak) {
          sum_v[bin] += r;
          ++n_v[bin];
        } else if (a < 0.9 * peak) {
          sum_b[bin] += r;
          ++n_b[bin];
        }
      }
      (e >= 0 ? peak_t : peak_c) = std::max(peak, a);
    }
    if (!across_tests) compare_bins();
  }
  compare_bins();
  ev.z = var > 0 ? diff / std::sqrt(var) : 0.0;
  return ev;
}

}  // namespace viscera::lab
