#pragma once  // SPDX-License-Identifier: Apache-2.0
// What one physics tick may cost. The explicit integrator takes ceil(1 / (rate dt)) sub-steps per
// tick, and a stiffer material or a finer mesh shortens dt without bound: Young's modulus 1e20 Pa
// on the bundled liver gives dt = 2.8e-12 s, hundreds of millions of sub-steps per tick. The
// server takes session requests, releases silent clients and stops only between ticks, so a tick
// must stay short; a scene, material or rate whose tick would not is refused, and the refusal names
// the stable step, the sub-steps it needs and the limit (docs/SCENE.md, "What a tick may cost").
#include <string>

namespace viscera::runtime {

struct TickBudget {
  /// Longest a tick may take on this machine [s]. At 0.1 s the organ still moves ten times a
  /// second and session requests and the lease are served within 0.1 s; a tick longer than its
  /// slot but within this (the 96k liver: about 30 ms) runs slower than real time, and the server
  /// says so (tick_cost).
  double max_tick_s = 0.1;
  /// Sub-steps per tick whatever the machine (a bound checked before anything is timed).
  long max_substeps = 10'000;
};

/// Sub-steps of the explicit step `dt_s` in one tick of `rate_hz`.
long substeps_per_tick(double dt_s, double rate_hz);

/// What a tick of `rate_hz` costs: "4 sub-steps of 9.76 ms = 39 ms per tick", and when that is
/// longer than the tick's slot ", slower than real time: about 26 ticks/s (2.6% of real time)".
std::string tick_cost(double dt_s, double substep_cost_s, double rate_hz);

/// Throws InputError(source, 0, field, why) unless a tick of `rate_hz` fits the budget: dt finite
/// and positive, at most max_substeps sub-steps, and sub-steps x `substep_cost_s` (measured on
/// this machine) at most max_tick_s. `substep_cost_s` <= 0: not measured, only the first two hold.
void check_tick_budget(double dt_s, double substep_cost_s, double rate_hz, const TickBudget& budget, const std::string& source,
                       const std::string& field);

}  // namespace viscera::runtime
