#include "viscera/console/force_decimator.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

namespace viscera::console {

void ForceDecimator::add(const protocol::Force& f) {
  Window& w = windows_[f.instrument_id];
  if (w.opened_s < 0) {
    w.s = ForceSummary{};
    w.s.instrument_id = f.instrument_id;
    w.opened_s = now_s_;
  }
  const double magnitude = std::hypot(f.force[0], f.force[1], f.force[2]);
  w.s.peak_n = std::max(w.s.peak_n, magnitude);
  w.s.max_edge_strain = std::max(w.s.max_edge_strain, f.max_edge_strain);
  w.s.tip_strain = std::max(w.s.tip_strain, f.tip_strain);
  w.s.t_s = 1e-9 * static_cast<double>(f.server_stamp_ns);
  w.s.force = f.force;
  w.s.contact_point = f.contact_point;
  w.s.in_contact = f.in_contact;
  ++w.s.samples;
}

std::vector<ForceSummary> ForceDecimator::flush(double now_s) {
  now_s_ = now_s;
  std::vector<ForceSummary> out;
  for (auto& [id, w] : windows_)
    if (w.opened_s >= 0 && now_s - w.opened_s >= period_s_) {
      out.push_back(w.s);
      w.opened_s = -1;
    }
  return out;
}

}  // namespace viscera::console
