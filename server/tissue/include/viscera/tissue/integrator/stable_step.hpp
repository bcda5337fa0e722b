#pragma once  // SPDX-License-Identifier: Apache-2.0
#include <span>
#include <vector>

#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

struct StableStep {
  double dt_s;  ///< critical step 2 / omega_max of symplectic Euler [s]
  double omega_max_rad_s;  ///< bound on the highest natural frequency
  std::size_t element;  ///< the element that sets it
};

/// Critical explicit time step from the mesh and the material, by the element eigenvalue bound
/// (Irons): omega_max^2 <= max_e lambda_max(M_e^-1 K_e), with K_e the model's tangent at rest and
/// M_e the element's lumped mass rho_e V_e / 4 per vertex. Never larger than the true global
/// limit; the integrator multiplies it by a safety factor for finite-strain stiffening.
StableStep critical_time_step(const ForceModel& model, std::span<const double> density_kg_m3);

/// Each element's bound on its highest natural frequency [rad/s], sqrt(lambda_max(M_e^-1 K_e)) as
/// in critical_time_step (whose undamped step is 2 / the largest of them).
std::vector<double> element_frequencies(const ForceModel& model, std::span<const double> density_kg_m3);
/// The same for one element of the given density.
double element_frequency(const ForceModel& model, std::size_t e, double density_kg_m3);
/// The same where it may exceed `omega_rad_s`; elsewhere an upper bound of it that does not
/// (from the tangent's trace and its largest absolute row sum, a tenth of the cost of the 12x12
/// eigenvalues): for a rule that acts only on the elements above a frequency.
double element_frequency_above(const ForceModel& model, std::size_t e, double density_kg_m3, double omega_rad_s);

/// Estimate of the global critical step from the highest natural frequency of the free
/// coordinates: power iteration on M^-1/2 K M^-1/2, K applied through central differences of the
/// forces at rest (the unrelaxed response). The Rayleigh quotient approaches omega_max^2 from
/// below, so the estimate is inflated by `margin` (omega^2 x margin). Deterministic (fixed start
/// vector). Typically 2-3.5x longer than the element bound; its safety rests on the margin and on
/// the integrator's instability check, so it is an option, not the default.
StableStep global_time_step(const ForceModel& model, std::span<const double> masses, std::span<const char> constrained, int iterations = 300,
                            double margin = 1.05);

}  // namespace viscera::tissue
