#include "viscera/runtime/tick_budget.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <cstdio>

#include "viscera/common/input_error.hpp"

namespace viscera::runtime {

using common::InputError;
using common::short_number;

long substeps_per_tick(double dt_s, double rate_hz) {
  // As ExplicitIntegrator::advance divides a tick: equal sub-steps no longer than dt.
  const double n = std::ceil(1.0 / (rate_hz * dt_s) * (1 - 1e-12));
  return n >= 1e15 ? static_cast<long>(1e15) : static_cast<long>(n);
}

namespace {
/// Three significant digits, whole numbers from 1000 up (a figure measured on a shared machine).
std::string figure(double v) {
  char b[32];
  std::snprintf(b, sizeof b, v >= 1000 ? "%.0f" : "%.3g", v);
  return b;
}
}  // namespace

std::string tick_cost(double dt_s, double substep_cost_s, double rate_hz) {
  const long n = substeps_per_tick(dt_s, rate_hz);
  const double tick_s = static_cast<double>(n) * substep_cost_s;
  std::string s = std::to_string(n) + " sub-step" + (n == 1 ? "" : "s") + " of " + figure(1e6 * substep_cost_s) + " us = " + figure(1e3 * tick_s) +
                  " ms per " + figure(1e3 / rate_hz) + " ms tick";
  if (tick_s > 1.0 / rate_hz)
    s += ", slower than real time: about " + figure(std::floor(1.0 / tick_s)) + " ticks/s (" + figure(100.0 / (tick_s * rate_hz)) + "% of real time)";
  return s;
}

void check_tick_budget(double dt_s, double substep_cost_s, double rate_hz, const TickBudget& budget, const std::string& source,
                       const std::string& field) {
  if (!std::isfinite(dt_s) || !(dt_s > 0))
    throw InputError(source, 0, field, "gives an explicit step of " + short_number(dt_s) + " s, which cannot be run (not a positive number)");
  const double tick_s = 1.0 / rate_hz;
  const double needed = std::ceil(tick_s / dt_s * (1 - 1e-12));
  const std::string step = "the stable explicit step is " + short_number(dt_s) + " s, so a " + short_number(1e3 * tick_s) + " ms tick needs " +
                           short_number(needed) + " sub-steps";
  if (needed > static_cast<double>(budget.max_substeps))
    throw InputError(source, 0, field, step + ", more than the " + std::to_string(budget.max_substeps) + " any tick may take");
  if (substep_cost_s <= 0) return;
  const double limit = std::floor(budget.max_tick_s / substep_cost_s);
  if (needed > limit)
    throw InputError(source, 0, field,
                     step + " of " + short_number(1e6 * substep_cost_s) +
                         " us each (measured here) = " + short_number(1e3 * needed * substep_cost_s) + " ms per tick; a tick may take at most " +
                         short_number(1e3 * budget.max_tick_s) + " ms, which is " + short_number(limit) +
                         " sub-steps on this machine (viscera-server --max-tick-ms)");
}

}  // namespace viscera::runtime
