#include "viscera/runtime/stiffening_limit.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"

namespace viscera::runtime {

using common::InputError;
using common::short_number;
using tissue::ExplicitIntegrator;
using tissue::GpsMechanisms;
using tissue::GpsStiffening;

namespace {

constexpr double kLargestB = 1000;  // the material files' range

/// A compressed edge's tension in the edge-map form against the linear one, at strain -e: the
/// map's secant (1 - exp(-B e)) / (B e).
double edge_map_compression_share(double b, double e) {
  const double x = b * e;
  return x < 1e-12 ? 1.0 : -std::expm1(-x) / x;
}

/// Three significant digits.
std::string three_digits(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

bool edge_map_holds(const GpsMechanisms& mech, double strain) {
  return mech.stiffening.form != GpsStiffening::Form::edge_map || edge_map_compression_share(mech.stiffening.b, strain) >= 0.5;
}

}  // namespace

double allowed_substep_growth(double dt_s, double substep_cost_s, double rate_hz, const TickBudget& budget) {
  const double rest = std::ceil(1.0 / (rate_hz * dt_s) * (1 - 1e-12));  // sub-steps per tick at rest
  double allowed = std::min(ExplicitIntegrator::kMaxStiffenedSubSteps, static_cast<double>(budget.max_substeps) / rest);
  if (substep_cost_s > 0) allowed = std::min(allowed, budget.max_tick_s / (substep_cost_s * rest));
  return allowed;
}

bool stiffening_runs(const GpsMechanisms& mech, double largest_edge_strain, double allowed) {
  const double strain = ExplicitIntegrator::headroom_strain(largest_edge_strain);
  return std::sqrt(mech.stiffness_growth(strain)) <= allowed && edge_map_holds(mech, strain);
}

double largest_stiffening(GpsMechanisms mech, double largest_edge_strain, double allowed) {
  // Both rules are monotone in B: the growth rises with it, the edge map's share falls.
  mech.stiffening.b = 0;
  if (!stiffening_runs(mech, largest_edge_strain, allowed)) return 0;
  mech.stiffening.b = kLargestB;
  if (stiffening_runs(mech, largest_edge_strain, allowed)) return kLargestB;
  double lo = 0, hi = kLargestB;
  while (hi - lo > 1e-3 * std::max(1.0, lo)) {
    mech.stiffening.b = 0.5 * (lo + hi);
    (stiffening_runs(mech, largest_edge_strain, allowed) ? lo : hi) = mech.stiffening.b;
  }
  return lo;
}

void check_stiffening(const GpsMechanisms& mech, double largest_edge_strain, double allowed, const std::string& source) {
  if (stiffening_runs(mech, largest_edge_strain, allowed)) return;
  const double strain = ExplicitIntegrator::headroom_strain(largest_edge_strain);
  const double growth = std::sqrt(mech.stiffness_growth(strain));
  const std::string at =
      "at edge strain " + three_digits(strain) + " (organ.largest_edge_strain " + short_number(largest_edge_strain) + " + headroom)";
  const std::string limit =
      "at most " + three_digits(allowed) +
      (allowed < ExplicitIntegrator::kMaxStiffenedSubSteps ? " fit this tick's budget (viscera-server --max-tick-ms)"
                                                           : ": past that the integrator calls the organ unstable and resets it");
  const double largest = largest_stiffening(mech, largest_edge_strain, allowed);
  if (!mech.stiffening.active() || largest == 0)
    throw InputError(
        source, 0, "viscoelasticity.compression_ratio",
        short_number(mech.asymmetry.compression_ratio) + " needs " + three_digits(growth) + " times the explicit sub-steps " + at + "; " + limit);
  const std::string lower = "; this organ takes B up to " + short_number(std::floor(largest * 10) / 10) + " in this form and shape";
  if (growth > allowed)
    throw InputError(
        source, 0, "viscoelasticity.qlv_stiffening",
        short_number(mech.stiffening.b) + " needs " + three_digits(growth) + " times the explicit sub-steps " + at + ", " + limit + lower);
  throw InputError(source, 0, "viscoelasticity.qlv_stiffening",
                   short_number(mech.stiffening.b) + " in the edge-map form: a compressed edge carries " +
                       three_digits(edge_map_compression_share(mech.stiffening.b, strain)) + " of the linear tension " + at +
                       ", below the 0.5 without which a deep press collapses the organ (\"qlv_form\": \"energy\" has no such bound)" + lower);
}

}  // namespace viscera::runtime
