#pragma once  // SPDX-License-Identifier: Apache-2.0
// The lab's family of 1D constitutive laws (a homogeneous specimen: uniaxial or simple shear),
// built as the tissue core builds its GPS: an elastic shape s(eps) and a relaxation operator on it,
//     sigma(t) = E s(t) + eta ds/dt + sum_l E_l h_l(t),   h_l = int exp(-(t-u)/tau_l) ds(u),
// with memory variables h_l updated exactly for s linear between samples (tissue::MemoryStep's
// recurrence). The baseline is what published simulators use: linear elasticity with Kelvin-Voigt
// damping (s = eps, no h_l). Each named mechanism extends it:
//   broadband_relaxation          E_l on log-spaced tau_l over the data's time scales (memory variables)
//   strain_stiffening             one of three forms, chosen by the fit:
//                                   exponential (Fung, 1D): s = (exp(B eps) - 1) / B
//                                   odd exponential:        s = sign(eps) (exp(B |eps|) - 1) / B
//                                   odd polynomial:         s = eps (1 + B^2 eps^2 / 6)
//                                   Ogden (one term, incompressible, exponent a = B), normalised to
//                                   s'(0) = 1: uniaxial, with the stretch l = 1 + eps,
//                                     s = 2/(3a) (l^(a-1) - l^(-a/2-1));
//                                   simple shear, with l = g/2 + sqrt(1 + g^2/4),
//                                     s = 2/a (l^a - l^-a) / (l + 1/l)   (odd in g)
//                                 in simple shear only the odd forms and Ogden's shear response (an
//                                 isotropic solid's shear stress is odd in the shear strain)
//   tension_compression_asymmetry s = eps (eps >= 0), r eps (eps < 0)
//   first_load_softening          s = eps on the virgin curve, (1 - d (1 - |eps|/m)) eps below the
//                                 previous extreme m (Ogden-Roxburgh-like softening on reloading);
//                                 where tests carry their specimen's history (test_history.hpp), a
//                                 test starts with m = k times the extreme of the tests before it:
//                                 the fraction k kept through the rests (1: none recovers, 0: all)
//   contact_take_up               a property of the test, not of the tissue, offered only where the
//                                 data set declares platens (a specimen compressed between plates it
//                                 is not bonded to): the platens close a gap c before they load it,
//                                 so the specimen's own strain is min(0, eps + c) (a toe), and they
//                                 cannot pull: the stress is min(0, sigma) (loss of contact)
// For given nonlinear parameters (B, r, d) the stress is linear in (E, eta, E_l) >= 0.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "viscera/lab/dataset.hpp"

namespace viscera::lab {

enum class Mechanism { broadband_relaxation, strain_stiffening, tension_compression_asymmetry, first_load_softening, contact_take_up };
inline constexpr std::array<Mechanism, 5> kMechanisms{Mechanism::broadband_relaxation, Mechanism::strain_stiffening,
                                                      Mechanism::tension_compression_asymmetry, Mechanism::first_load_softening,
                                                      Mechanism::contact_take_up};
/// Whether a mechanism belongs to the test rather than to the tissue (left out of the material
/// handed to the organ).
inline bool of_the_test(Mechanism m) { return m == Mechanism::contact_take_up; }
const char* name(Mechanism m);
/// Parses a mechanism name; false if unknown.
bool parse_mechanism(const std::string& s, Mechanism* out);

enum class StiffeningForm { exponential, odd_exponential, odd_polynomial, ogden };
const char* name(StiffeningForm f);
/// Parses a form's name; false if unknown.
bool parse_stiffening_form(const std::string& s, StiffeningForm* out);

struct MaterialModel {
  unsigned mechanisms = 0;  ///< bit (1 << Mechanism)
  /// The data's elastic response must be odd in the strain (simple shear of an isotropic solid):
  /// the fit offers only odd stiffening forms, and Ogden's form is its shear response. Set from
  /// the data set's mode.
  bool odd_only = false;
  /// The specimen sat between platens it is not bonded to (dataset.json "contact": "platens"): they
  /// cannot pull, so every predicted stress is min(0, sigma), and contact_take_up is a candidate.
  /// Set from the data set.
  bool platens = false;
  /// Some test starts where earlier tests on its specimen left it (TestData::before_tension,
  /// before_compression): first-load softening's kept fraction is then a parameter. Set from the data set.
  bool history_carried = false;
  StiffeningForm stiffening_form = StiffeningForm::exponential;
  double stiffening_b = 0.0;
  double compression_ratio = 1.0;
  double softening_d = 0.0;
  double softening_kept = 1.0;  ///< first_load_softening: k, the fraction of the earlier tests' extremes a test starts with
  double contact_strain = 0.0;  ///< contact_take_up: the gap the platens close before they load, as a strain
  double modulus_pa = 0.0;
  double viscosity_pa_s = 0.0;
  std::vector<double> relaxation_time_s;  ///< broadband only
  std::vector<double> relaxation_modulus_pa;  ///< broadband only

  bool has(Mechanism m) const { return mechanisms & (1u << static_cast<unsigned>(m)); }
  /// "kelvin_voigt_linear" or "kelvin_voigt_linear + broadband_relaxation + ...".
  std::string describe() const;
  /// Number of free parameters (non-zero linear ones and the nonlinear ones).
  int parameter_count() const;
};

/// The model as it applies to a data set's tests: odd_only from its mode, platens from its contact,
/// history_carried from its tests.
MaterialModel for_dataset(MaterialModel m, const Dataset& d);

/// The strain the specimen itself undergoes at the test's strain eps: eps, or with contact_take_up
/// min(0, eps + c).
double specimen_strain(const MaterialModel& m, double eps);

/// The elastic shape s(eps) of a model along one history (first-load softening remembers the
/// largest strain seen in tension and in compression).
struct ElasticShape {
  const MaterialModel& m;
  double max_tension = 0.0, max_compression = 0.0;
  double value(double eps) const;
  /// The strain whose shape is s, with the history so far (s is increasing in eps).
  double strain_for(double s) const;
  /// Records eps in the history.
  void advance(double eps);
};

/// The shape at the start of test t, with what the tests before it left on its specimen
/// (TestData::before_tension and before_compression; test_history.hpp).
ElasticShape shape_at_start(const MaterialModel& m, const TestData& t);

/// Elastic shape s at every sample of a strain history, from `start`.
std::vector<double> elastic_shape(ElasticShape start, const std::vector<double>& strain);

/// Columns of the linear model at the samples: s, ds/dt, h_l for each tau_l, along the strain's
/// command path (command_path.hpp).
Eigen::MatrixXd basis(const MaterialModel& m, const TestData& t);

/// The parameters the stress is linear in, in basis() column order: E, eta, E_l.
Eigen::VectorXd linear_coefficients(const MaterialModel& m);
void set_linear_coefficients(MaterialModel& m, const Eigen::VectorXd& c);

/// Stress from the measured strain (the equation the fit minimises, for any control); between
/// platens, never a pull.
std::vector<double> predict_stress(const MaterialModel& m, const TestData& t);

/// Log-spaced relaxation times, one per decade, covering the sampling intervals and durations.
std::vector<double> relaxation_times_for(const Dataset& d);

}  // namespace viscera::lab
