#pragma once
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

/// The material file's text for `m` fitted to `d`, named `name`; empty, with `why`, for a law the
/// GPS cannot represent (specimen_supports: Ogden's form; stiffening or asymmetry in simple shear).
std::string material_file_text(const MaterialModel& m, const Dataset& d, const std::string& name, std::string* why);

}  // namespace viscera::lab
