#include "viscera/lab/noise_check.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace viscera::lab {

HoldNoise noise_in_holds(const TestData& t, double window_s) {
  const bool stress_control = t.control == Control::stress;
  const std::vector<double>& held = stress_control ? t.stress_pa : t.strain;
  const std::vector<double>& measured = stress_control ? t.strain : t.stress_pa;
  const std::size_t n = t.time_s.size();
  HoldNoise r;
  if (n < 27) return r;
  const double dt = (t.time_s.back() - t.time_s.front()) / static_cast<double>(n - 1);
  const std::size_t half = std::max<std::size_t>(4, static_cast<std::size_t>(std::lround(0.5 * window_s / dt)));
  const std::size_t w = 2 * half + 1;
  r.window_s = static_cast<double>(w) * dt;
  const auto [lo, hi] = std::minmax_element(held.begin(), held.end());
  const double tol = 4 * noise_from_second_differences(held) + 1e-6 * (*hi - *lo);
  std::vector<double> residual;
  std::size_t start = 0;
  for (std::size_t k = 1; k <= n; ++k) {
    if (k < n && std::abs(held[k] - held[start]) <= tol) continue;
    const std::size_t end = k;  // held over [start, end)
    if (end - start >= 3 * w) {
      ++r.holds;
      double sum = 0;
      const std::size_t first = start + w;  // the first window of the hold is left out
      for (std::size_t j = first - half; j <= first + half; ++j) sum += measured[j];
      for (std::size_t c = first; c + half < end; ++c) {
        residual.push_back(measured[c] - sum / static_cast<double>(w));
        if (c + half + 1 < end) sum += measured[c + half + 1] - measured[c - half];
      }
    }
    start = k;
  }
  if (residual.empty()) return r;
  r.samples = residual.size();
  for (double& x : residual) x = std::abs(x);
  std::nth_element(residual.begin(), residual.begin() + static_cast<long>(residual.size() / 2), residual.end());
  // A residual about a w-sample mean has variance sd^2 (1 - 1/w) for white noise.
  r.sd = residual[residual.size() / 2] / 0.6745 / std::sqrt(1.0 - 1.0 / static_cast<double>(w));
  return r;
}

}  // namespace viscera::lab
