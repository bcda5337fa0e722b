#pragma once  // SPDX-License-Identifier: Apache-2.0
// Selective mass scaling: the explicit step is set by the few smallest, stiffest elements
// (slivers left by meshing and refinement), not by the organ. Giving just those elements more
// mass lengthens the stable step for a small, stated amount of added mass, as explicit FE codes
// do (conventional mass scaling limited to the critical elements). Statics are unchanged (mass
// does not enter equilibrium); inertia grows where mass was added, so the added fraction is a
// modelling choice that the caller states and reports.
#include <span>
#include <vector>

#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

struct MassScaling {
  std::vector<double> density_kg_m3;  ///< per element, >= the given density
  double added_mass_fraction = 0;  ///< added mass / the organ's mass
  std::size_t scaled_elements = 0;  ///< elements that got heavier
  /// Every element's own critical step (2 / element_frequencies) is now at least this [s].
  double min_element_step_s = 0;
};

/// Adds `added_mass_fraction` of the organ's mass to its elements with the shortest critical
/// steps: each element whose own step 2 / omega_e is below a threshold T gets the density that
/// brings its step to T (rho_e (T omega_e / 2)^2), T chosen so that the mass added is exactly the
/// fraction. Element steps are the eigenvalue bounds of critical_time_step; the global step they
/// allow is found as usual (critical_time_step or global_time_step on the new densities).
/// Deterministic. Throws std::invalid_argument for a fraction outside [0, 10].
MassScaling scale_small_element_masses(const ForceModel& model, std::span<const double> density_kg_m3, double added_mass_fraction);

/// Local mass scaling for the elements a cut made (docs/CUTTING.md): each of `elements` whose own
/// critical step 2 / omega_e is below `min_step_s` gets the density that brings it there, so a
/// cut never shortens the step the organ runs at. Returns the mass added [kg] (inertia only, as
/// above).
double hold_element_steps(const ForceModel& model, std::span<double> density_kg_m3, std::span<const std::int32_t> elements, double min_step_s);

}  // namespace viscera::tissue
