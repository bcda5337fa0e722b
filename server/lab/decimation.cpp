#include "viscera/lab/decimation.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <vector>

#include "viscera/lab/analysis.hpp"

namespace viscera::lab {

namespace {

TestData decimate_test(const TestData& t, std::size_t max_points) {
  const std::size_t n = t.time_s.size();
  const auto [lo, hi] = std::minmax_element(t.strain.begin(), t.strain.end());
  const double span_t = t.time_s.back() - t.time_s.front();
  const double span_e = *hi - *lo > 0 ? *hi - *lo : 1.0;
  // Cumulative path length in normalised (time, strain).
  std::vector<double> s(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) {
    const double dt = (t.time_s[k] - t.time_s[k - 1]) / span_t, de = (t.strain[k] - t.strain[k - 1]) / span_e;
    s[k] = s[k - 1] + std::sqrt(dt * dt + de * de);
  }
  TestData out = t;  // its file, control, specimen and history; the rows chosen below
  out.time_s.clear();
  out.strain.clear();
  out.stress_pa.clear();
  out.stress_sd_pa.clear();
  const double noise = noise_level_pa(t);
  std::size_t last = n;  // index kept last
  for (std::size_t j = 0; j < max_points; ++j) {
    const double target = s.back() * static_cast<double>(j) / static_cast<double>(max_points - 1);
    std::size_t k = static_cast<std::size_t>(std::lower_bound(s.begin(), s.end(), target) - s.begin());
    k = std::min(k, n - 1);
    if (k == last) continue;
    last = k;
    out.time_s.push_back(t.time_s[k]);
    out.strain.push_back(t.strain[k]);
    out.stress_pa.push_back(t.stress_pa[k]);
    out.stress_sd_pa.push_back(t.stress_sd_pa.empty() ? noise : t.stress_sd_pa[k]);
  }
  return out;
}

}  // namespace

Dataset decimate(const Dataset& d, std::size_t max_points) {
  Dataset out = d;
  for (TestData& t : out.tests)
    if (t.time_s.size() > max_points) t = decimate_test(t, std::max<std::size_t>(max_points, 3));
  return out;
}

}  // namespace viscera::lab
