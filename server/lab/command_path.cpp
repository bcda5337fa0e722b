#include "viscera/lab/command_path.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

namespace viscera::lab {

double CommandPath::rate_at_sample(std::size_t k) const {
  const std::size_t j = sample[k];
  return j == 0 ? 0.0 : (value[j] - value[j - 1]) / (time_s[j] - time_s[j - 1]);
}

double CommandPath::at(double t) const {
  if (t <= time_s.front()) return value.front();
  if (t >= time_s.back()) return value.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(time_s.begin(), time_s.end(), t) - time_s.begin());
  return value[k - 1] + (value[k] - value[k - 1]) * (t - time_s[k - 1]) / (time_s[k] - time_s[k - 1]);
}

CommandPath command_path(const std::vector<double>& t, const std::vector<double>& v) {
  const std::size_t n = t.size();
  std::vector<double> slope(n, 0.0);  // slope[k]: over (t[k-1], t[k]); slope[0] = 0
  for (std::size_t k = 1; k < n; ++k) slope[k] = (v[k] - v[k - 1]) / (t[k] - t[k - 1]);
  CommandPath p;
  const auto add = [&p](double time, double value) {
    p.time_s.push_back(time);
    p.value.push_back(value);
  };
  // Already moving at the first sample (its interval agrees with the next better than with rest)
  // on a line that left zero less than one interval before: start from rest there.
  if (n > 2 && slope[1] != 0.0 && std::abs(slope[1]) > std::abs(slope[2] - slope[1])) {
    const double since = v[0] / slope[1];
    if (since > 0 && since <= t[1] - t[0]) add(t[0] - since, 0.0);
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (k >= 1 && k + 2 < n && std::abs(slope[k + 2] - slope[k + 1]) < std::abs(slope[k] - slope[k - 1])) {
      // The corner between the line through the path's last piece and the line after sample k.
      const std::size_t j = p.time_s.size() - 1;
      const double a = j == 0 ? 0.0 : (p.value[j] - p.value[j - 1]) / (p.time_s[j] - p.time_s[j - 1]);
      const double b = slope[k + 1];
      if (a != b) {
        const double corner = (v[k] - v[k - 1] - b * t[k] + a * t[k - 1]) / (a - b);
        // A corner within a thousandth of the interval from a sample changes nothing a test
        // resolves and would only make a vanishing step for the specimen.
        const double margin = 1e-3 * (t[k] - t[k - 1]);
        if (corner > t[k - 1] + margin && corner < t[k] - margin) add(corner, v[k - 1] + a * (corner - t[k - 1]));
      }
    }
    p.sample.push_back(p.time_s.size());
    add(t[k], v[k]);
  }
  return p;
}

}  // namespace viscera::lab
