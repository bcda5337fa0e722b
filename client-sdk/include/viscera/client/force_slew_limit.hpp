#pragma once  // SPDX-License-Identifier: Apache-2.0
// The last guard between the server and a hand: the force commanded to a device changes by at most
// a set amount per device period, whatever arrives from the local force model (docs/FAULTS.md, "The
// force on the hand"). A step the server or the network makes (a reset under a deep press, a
// contact that flickers, a stiff material) reaches the hand as a ramp of that slope; the fades of
// LocalForceRenderer decide where the force goes, this decides how fast it may get there.
//
// The default, 1 N/ms, is argued in docs/FAULTS.md: four times the fastest change a pressing hand
// makes on the stiffest contact the scenes render (1000 N/m at the 0.5 m/s tool speed limit:
// 0.5 N/ms, the tissue in series makes it less), so ordinary contact is never touched, and a
// device's whole range (15 N) takes 15 ms, a firm push instead of a blow.
#include "viscera/protocol/messages.hpp"

namespace viscera::client {

class ForceSlewLimit {
 public:
  /// `n_per_s`: the largest change of the force [N/s] (infinite: no limit); `period_s`: the device's
  /// period, the longest time one step may count (after a stall the force still moves by one
  /// period's worth per period).
  ForceSlewLimit(double n_per_s, double period_s) : rate_(n_per_s), period_(period_s) {}
  /// The force to command at `t_s` on the way to `target` (the first call starts from zero).
  protocol::Vector3 limit(const protocol::Vector3& target, double t_s);
  /// The force commanded last.
  const protocol::Vector3& last() const { return last_; }
  /// How often the limit changed the force, and the largest change it was asked for in one call [N].
  long limited() const { return limited_; }
  double largest_step_asked_n() const { return largest_asked_; }

 private:
  double rate_, period_;
  protocol::Vector3 last_{};
  double last_t_ = -1;
  long limited_ = 0;
  double largest_asked_ = 0;
};

}  // namespace viscera::client
