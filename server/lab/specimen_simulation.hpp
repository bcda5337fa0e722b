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

/// Fung stiffening on the specimen: the GPS takes it in its energy form (conservative, symmetric
/// tangent), whose B is calibrated so that the specimen's instantaneous elastic response to the
/// mode's loading matches the law's (exp(B e) - 1) / B over the data's strain range (the 3D
/// energy form stiffens faster than the 1D law at the same B).
struct StiffeningCalibration {
  double law_b = 0, gps_b = 0;
  double strain_lo = 0, strain_hi = 0;
  double uncalibrated_mismatch = 0;  ///< relative RMS of the specimen's curve against the law's at B_gps = B
  double mismatch = 0;               ///< the same at the calibrated B_gps
};
StiffeningCalibration calibrate_stiffening(const MaterialModel& m, const Dataset& d);

struct SpecimenResult {
  bool supported = false;
  std::string note;                 ///< why not, or what is approximated
  std::vector<double> stress_pa;    ///< at the data times (strain control: predicted; stress control: imposed)
  std::vector<double> strain;       ///< at the data times (stress control: predicted)
  double rms_pa = 0.0;              ///< strain control: RMS stress error; stress control: RMS strain error x modulus
  long steps = 0, newton_iterations = 0, step_cuts = 0;
  StiffeningCalibration stiffening;  ///< when the model stiffens
};

/// Which models the GPS can represent: Kelvin-Voigt, memory variables (broadband), Fung
/// stiffening under uniaxial loading (the GPS's energy form, B calibrated: see
/// StiffeningCalibration); not the law's stiffening in simple shear (no isotropic solid has it).
bool specimen_supports(const MaterialModel& m, Mode mode, std::string* why);

/// `calibration`: calibrate_stiffening(m, d), if already known (it is computed otherwise).
SpecimenResult simulate_specimen(const MaterialModel& m, const Dataset& d, const TestData& t,
                                 const StiffeningCalibration* calibration = nullptr);

}  // namespace viscera::lab
