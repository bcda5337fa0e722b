#pragma once
// What one physics tick may cost. The explicit integrator takes ceil(1 / (rate dt)) sub-steps per
// tick, and a stiffer material or a finer mesh shortens dt without bound: Young's modulus 1e20 Pa
// on the bundled liver gives dt = 2.8e-12 s, hundreds of millions of sub-steps per tick. The
// server takes session requests, releases silent clients and stops only between ticks, so a tick
// must stay short; a scene, material or rate whose tick would not is refused, and the refusal names
// the stable step, the sub-steps it needs and the limit (docs/SCENE.md, "What a tick may cost").
#include <string>

namespace viscera::runtime {

struct TickBudget {
  /// Longest a tick may take on this machine [s]: 1/30 s keeps the server answering and the live
  /// view at the paper's floor of 30 updates per second.
  double max_tick_s = 1.0 / 30.0;
  /// Sub-steps per tick whatever the machine (a bound checked before anything is timed).
  long max_substeps = 10'000;
};

/// Sub-steps of the explicit step `dt_s` in one tick of `rate_hz`.
long substeps_per_tick(double dt_s, double rate_hz);

/// Throws InputError(source, 0, field, why) unless a tick of `rate_hz` fits the budget: dt finite
/// and positive, at most max_substeps sub-steps, and sub-steps x `substep_cost_s` (measured on
/// this machine) at most max_tick_s. `substep_cost_s` <= 0: not measured, only the first two hold.
void check_tick_budget(double dt_s, double substep_cost_s, double rate_hz, const TickBudget& budget, const std::string& source,
                       const std::string& field);

}  // namespace viscera::runtime
