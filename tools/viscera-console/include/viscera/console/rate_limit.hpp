#pragma once  // SPDX-License-Identifier: Apache-2.0
// A token bucket: `rate` requests a second on average, bursts of up to `burst`.
#include <algorithm>

namespace viscera::console {

class RateLimit {
 public:
  RateLimit(double rate_per_s, double burst) : rate_(rate_per_s), burst_(burst), tokens_(burst) {}
  /// Whether a request at time `t_s` [s, monotonic] may pass (and spends a token if so).
  bool allow(double t_s) {
    if (last_s_ >= 0) tokens_ = std::min(burst_, tokens_ + (t_s - last_s_) * rate_);
    last_s_ = t_s;
    if (tokens_ < 1) return false;
    tokens_ -= 1;
    return true;
  }

 private:
  double rate_, burst_, tokens_;
  double last_s_ = -1;
};

}  // namespace viscera::console
