#pragma once  // SPDX-License-Identifier: Apache-2.0
// The p-quantile of samples (the element at rank floor(p (n - 1)) in sorted order, no
// interpolation): step times, jitter and round trips are reported this way everywhere.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace viscera::common {

/// 0 for no samples. Takes the samples by value: it partially sorts them.
inline double percentile(std::vector<double> samples, double p) {
  if (samples.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(p * static_cast<double>(samples.size() - 1));
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(k), samples.end());
  return samples[k];
}

}  // namespace viscera::common
