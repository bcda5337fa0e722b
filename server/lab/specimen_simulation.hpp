#pragma once
// A test simulated on the specimen itself: the specimen meshed with tetrahedra, the boundary
// conditions of the mode, the measured loading history, inertia included, viscera's GPS with
// memory variables, the implicit integrator (backward Euler, CHOLMOD) stepping between samples
// with steps that start small after every sample and grow through long holds.
//  - uniaxial: frictionless grips (x held at x = 0, the x = L face pulled along x, lateral free);
//    nominal stress = reaction / (W T);
//  - simple shear: base held, every node restricted to motion along x, top moved (or loaded)
//    along x; shear stress = reaction / (L W).
#include <string>
#include <vector>

#include "dataset.hpp"
#include "material_model.hpp"

namespace viscera::lab {

struct SpecimenResult {
  bool supported = false;
  std::string note;                 ///< why not, or what is approximated
  std::vector<double> stress_pa;    ///< at the data times (strain control: predicted; stress control: imposed)
  std::vector<double> strain;       ///< at the data times (stress control: predicted)
  double rms_pa = 0.0;              ///< strain control: RMS stress error; stress control: RMS strain error x modulus
  long steps = 0, newton_iterations = 0, step_cuts = 0;
};

/// Which models the GPS can represent: Kelvin-Voigt, memory variables (broadband), Fung
/// stiffening (edge-wise in the GPS: an approximation of the uniaxial law).
bool specimen_supports(const MaterialModel& m, std::string* why);

SpecimenResult simulate_specimen(const MaterialModel& m, const Dataset& d, const TestData& t);

}  // namespace viscera::lab
