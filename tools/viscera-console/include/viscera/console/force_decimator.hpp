#pragma once  // SPDX-License-Identifier: Apache-2.0
// The 1 kHz forces cut down to what a plot needs: per instrument, one summary per period with the
// period's peak force magnitude kept (a short spike is never averaged or sampled away), the last
// force vector, contact, and the tissue-damage proxy's peak.
#include <cstdint>
#include <map>
#include <vector>

#include "viscera/protocol/messages.hpp"

namespace viscera::console {

struct ForceSummary {
  std::uint32_t instrument_id = 0;
  double t_s = 0;  ///< the last sample's server time [s]
  double peak_n = 0;  ///< the largest |F| in the period [N]
  protocol::Vector3 force{};  ///< the last sample's force [N]
  protocol::Vector3 contact_point{};  ///< [m]
  bool in_contact = false;  ///< in contact at the last sample
  double max_edge_strain = 0;  ///< the largest in the period
  double tip_strain = 0;  ///< the largest strain at the instrument in the period (schema 18)
  std::uint32_t samples = 0;
};

class ForceDecimator {
 public:
  explicit ForceDecimator(double period_s) : period_s_(period_s) {}
  void add(const protocol::Force& f);
  /// The summaries of the instruments whose period has ended by `now_s` (the bridge's clock [s]).
  std::vector<ForceSummary> flush(double now_s);

 private:
  struct Window {
    ForceSummary s;
    double opened_s = -1;  ///< when the period's first sample arrived (bridge clock); < 0: empty
  };
  double period_s_;
  double now_s_ = 0;
  std::map<std::uint32_t, Window> windows_;
};

}  // namespace viscera::console
