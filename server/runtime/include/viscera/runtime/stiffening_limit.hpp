#pragma once  // SPDX-License-Identifier: Apache-2.0
// Whether a strain-stiffening material can run at the deepest press its organ's scene expects
// (docs/SCENE.md, "Materials a press cannot break"). The explicit integrator shortens its sub-step
// by the square root of the material's stiffness growth at the strain it sees, and past
// ExplicitIntegrator::kMaxStiffenedSubSteps (64) sub-steps per step it calls the run unstable and
// the organ is reset: under a hand. So a material is refused unless, at the scene's
// largest_edge_strain (with the integrator's headroom, ExplicitIntegrator::headroom_strain):
//  - its stiffness growth needs at most 64 sub-steps per step, and a tick of them fits the tick's
//    budget (sub-steps and time, tick_budget.hpp);
//  - in the published edge-map form, a compressed edge's tension there is at least half the linear
//    one. That form maps each edge strain by g(e) = (exp(B e) - 1) / B >= -1 / B, so an element
//    compressed along all its edges resists with a force bounded by H / B and a deep press runs it
//    away (measured on the 1.5k liver pressed 3-3.5 cm at 2 cm/s: B = 3 holds, B = 4 and above
//    collapse, edge strains past 1.5). At the default largest strain (0.4) the rule lies between:
//    B <= 3.6. The energy form (same law in a bar) has no such bound: its tensions carry the other
//    edges' mapped strains, which grow without bound.
#include <string>

#include "viscera/runtime/tick_budget.hpp"
#include "viscera/tissue/gps/gps_mechanisms.hpp"

namespace viscera::runtime {

/// What a tick allows a stiffening material: at most this many times the rest step's sub-steps
/// (the integrator's cap, and the budget's sub-steps and time with `substep_cost_s` measured here,
/// <= 0: not measured) for a tick of `rate_hz` with the explicit step `dt_s` at rest.
double allowed_substep_growth(double dt_s, double substep_cost_s, double rate_hz, const TickBudget& budget);

/// Whether `mech` passes both rules at `largest_edge_strain` with sub-steps growing at most by
/// `allowed` (allowed_substep_growth).
bool stiffening_runs(const tissue::GpsMechanisms& mech, double largest_edge_strain, double allowed);

/// The largest Fung B of `mech`'s form and shape (its other parts as they are) that runs; 0 when
/// none does (the asymmetry alone is too stiff), and 1000 (the material files' limit) at most.
double largest_stiffening(tissue::GpsMechanisms mech, double largest_edge_strain, double allowed);

/// Throws common::InputError(source, 0, field, why) unless `mech` runs at `largest_edge_strain`;
/// the field is viscoelasticity.qlv_stiffening (or .compression_ratio when the asymmetry alone
/// is too stiff), and `why` names the growth, the sub-steps, the limit, the largest B this organ
/// takes and the scene's field that sets the strain.
void check_stiffening(const tissue::GpsMechanisms& mech, double largest_edge_strain, double allowed, const std::string& source);

}  // namespace viscera::runtime
