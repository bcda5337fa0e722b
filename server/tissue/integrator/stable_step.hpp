#pragma once
#include <span>

#include "model/force_model.hpp"

namespace viscera::tissue {

struct StableStep {
  double dt_s;              ///< critical step 2 / omega_max of symplectic Euler [s]
  double omega_max_rad_s;   ///< bound on the highest natural frequency
  std::size_t element;      ///< the element that sets it
};

/// Critical explicit time step from the mesh and the material, by the element eigenvalue bound
/// (Irons): omega_max^2 <= max_e lambda_max(M_e^-1 K_e), with K_e the model's tangent at rest and
/// M_e the element's lumped mass rho_e V_e / 4 per vertex. Never larger than the true global
/// limit; the integrator multiplies it by a safety factor for finite-strain stiffening.
StableStep critical_time_step(const ForceModel& model, std::span<const double> density_kg_m3);

}  // namespace viscera::tissue
