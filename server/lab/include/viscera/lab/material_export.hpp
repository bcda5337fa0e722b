#pragma once  // SPDX-License-Identifier: Apache-2.0
// From the data set to the organ: the material file (docs/MATERIAL.md) that carries a fitted law
// into the server's GPS as it is, every mechanism with its 3D calibration: the unrelaxed modulus
// and the relaxation spectrum as weights of it, the Kelvin-Voigt time, first-load softening, and
// the elastic shape (stiffening, asymmetry) in the energy form with the constants calibrated on
// the data set's specimen (specimen_simulation.hpp, GpsLaw). Poisson's ratio is the specimen's
// (kSpecimenPoissonRatio): uniaxial and shear tests do not determine it.
#include <string>

#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"

namespace viscera::lab {

/// A Kelvin-Voigt dashpot eta = E_u tau_kv is handed over as a Maxwell branch of this many times
/// the unrelaxed modulus and time tau_kv / it: the same viscosity below 1 / (2 pi tau), a bounded
/// stiffness above. The organ's explicit integrator cannot take the dashpot itself: its stable step
/// falls like dt_e^2 / (2 tau_kv) (dt_e the elastic step; 1.7 us for the titin baseline's 17 ms on
/// the 1.5k liver), while the branch shortens it by sqrt(1 + kDashpotBranchStiffness) = 1.41.
inline constexpr double kDashpotBranchStiffness = 1.0;

/// The material file's text for `m` fitted to `d`, named `name`; empty, with `why`, for a law the
/// GPS cannot represent (specimen_supports: Ogden's form; stiffening or asymmetry in simple shear).
/// A Kelvin-Voigt time becomes a Maxwell branch (kDashpotBranchStiffness), said in `note`.
std::string material_file_text(const MaterialModel& m, const Dataset& d, const std::string& name, std::string* why, std::string* note = nullptr);

}  // namespace viscera::lab
