#pragma once  // SPDX-License-Identifier: Apache-2.0
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

#include "viscera/lab/dataset.hpp"
#include "viscera/lab/material_model.hpp"
#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/gps/gps_mechanisms.hpp"

namespace viscera::lab {

/// The law's elastic shape on the specimen (Fung stiffening B, tension/compression asymmetry r):
/// the GPS takes it in its energy form (conservative, symmetric tangent; gps/fung_map.hpp), whose
/// constants are calibrated so that the specimen's instantaneous elastic response to the mode's
/// loading matches the law's over the data's strain range (B on the tension side, r on the
/// compression side): in 3D the edges across the load stiffen or soften too, so the same
/// constants would not give the same curve.
struct ShapeCalibration {
  double law_b = 0, gps_b = 0;  ///< Fung's B (0: none)
  double law_r = 1, gps_r = 1;  ///< compression ratio (1: symmetric)
  double strain_lo = 0, strain_hi = 0;
  double uncalibrated_mismatch = 0;  ///< relative RMS of the specimen's curve against the law's with the law's constants
  double mismatch = 0;  ///< the same with the calibrated constants
};
ShapeCalibration calibrate_elastic_shape(const MaterialModel& m, const Dataset& d);

struct SpecimenResult {
  bool supported = false;
  std::string note;  ///< why not, or what is approximated
  std::vector<double> stress_pa;  ///< at the data times (strain control: predicted; stress control: imposed)
  std::vector<double> strain;  ///< at the data times (stress control: predicted)
  double rms_pa = 0.0;  ///< strain control: RMS stress error; stress control: RMS strain error x modulus
  long steps = 0, newton_iterations = 0, step_cuts = 0;
  ShapeCalibration shape;  ///< when the model stiffens or is asymmetric
};

/// Which models the GPS can represent: Kelvin-Voigt, memory variables (broadband), first-load
/// softening (per edge, GpsViscoelasticity::first_load_softening), Fung stiffening and
/// tension/compression asymmetry under uniaxial loading (the GPS's energy form, calibrated: see
/// ShapeCalibration); not those two in simple shear (no isotropic solid has them).
bool specimen_supports(const MaterialModel& m, Mode mode, std::string* why);

/// Newton stops when the residual force is below this fraction of the test's noise times the
/// loaded area (or the integrator's relative tolerance, whichever is larger): it then moves the
/// measured stress by about a hundredth of the noise, far below what the comparison can see. A
/// relative tolerance alone asked for 5e-14 N on forces of newtons and could not be met; and on
/// the odd stiffening shapes Newton converges only linearly once edges cross zero strain (the
/// energy map's h'' jumps there: fung_map.hpp), so a tolerance that means nothing costs runs.
inline constexpr double kSpecimenResidualToNoise = 1e-2;

/// The law in the GPS's terms, as the specimen takes it and as a material file hands it to an
/// organ: unrelaxed modulus E_U = E + sum E_l, weights E_l / E_U on shear and bulk alike (the whole
/// elastic tension relaxes, as the law's), Kelvin-Voigt time eta / E_U; softening per edge; the
/// elastic shape in the energy form with its constants calibrated to the law's curve.
struct GpsLaw {
  tissue::GpsMechanisms mechanisms;
  double unrelaxed_modulus_pa = 0.0;  ///< the law's (uniaxial: Young's; simple shear: the shear modulus)
  ShapeCalibration shape;  ///< when the law stiffens or is asymmetric
};
GpsLaw gps_law(const MaterialModel& m, const Dataset& d, const ShapeCalibration* calibration = nullptr);

/// The specimen's Poisson's ratio: a uniaxial test with free lateral faces, or simple shear, does
/// not determine it, and at small strain the GPS's response to either does not depend on it.
inline constexpr double kSpecimenPoissonRatio = 0.3;

/// The specimen's isotropic elasticity for a law's modulus: uniaxial, it is Young's; simple
/// shear, the shear modulus (Young's = 2 G (1 + nu)).
tissue::Mat6 specimen_elasticity(double modulus_pa, bool shear);

/// `calibration`: calibrate_elastic_shape(m, d), if already known (it is computed otherwise).
/// `max_seconds` > 0: a run still going after this much wall time stops with a SimulationError
/// naming where it was (simulated time, steps, step cuts), so that an analysis never hangs.
SpecimenResult simulate_specimen(const MaterialModel& m, const Dataset& d, const TestData& t, const ShapeCalibration* calibration = nullptr,
                                 double max_seconds = 0.0);

/// The same test on the specimen built from given GPS mechanisms and unrelaxed elasticity (what a
/// material file gives the server: tissue::make_viscoelastic), not from a law.
SpecimenResult simulate_specimen(const tissue::GpsMechanisms& mechanisms, const tissue::Mat6& unrelaxed_elasticity, const Dataset& d,
                                 const TestData& t, double max_seconds = 0.0);

}  // namespace viscera::lab
