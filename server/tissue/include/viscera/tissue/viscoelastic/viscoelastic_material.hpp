#pragma once  // SPDX-License-Identifier: Apache-2.0
// From what a user states (elastic constants at a reference frequency, Q in shear and in bulk,
// the band, the number of mechanisms) to what the GPS needs: the unrelaxed elasticity and the
// memory-variable weights, shear and bulk sharing the relaxation frequencies. Also the
// Kelvin-Voigt baseline matched at the reference frequency.
#include <optional>
#include <string>
#include <vector>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/viscoelastic/constant_q_fit.hpp"

namespace viscera::tissue {

struct ViscoelasticSpec {
  /// constant_q: Q over a band (the paper's liver); kelvin_voigt: one relaxation time matched at
  /// the reference frequency; relaxation_spectrum: the moduli and times stated as they are (what
  /// viscera-lab fits: docs/LAB.md), the elasticity then being the unrelaxed one.
  enum class Model { constant_q, kelvin_voigt, relaxation_spectrum } model = Model::constant_q;
  double shear_q = 4.8;
  std::optional<double> bulk_q;  ///< none: the bulk response does not relax
  double band_low_hz = 0.01, band_high_hz = 10.0;
  int mechanisms = 3;
  double reference_frequency_hz = 2.0;
  double qlv_stiffening = 0.0;  ///< Fung's B (0: linear elastic response)
  /// How the stiffening enters the GPS (GpsStiffening::Form): the published edge map or the
  /// conservative energy form.
  GpsStiffening::Form qlv_form = GpsStiffening::Form::edge_map;
  double compression_ratio = 1.0;  ///< tension/compression asymmetry r (energy form only; 1: none)
  StiffeningShape qlv_shape = StiffeningShape::exponential;  ///< the stiffening law (odd shapes: energy form only)
  // relaxation_spectrum only: shear and bulk relax alike.
  std::vector<double> relaxation_times_s;  ///< tau_l
  std::vector<double> relaxation_weights;  ///< E_l / E_unrelaxed, one per time; their sum below 1
  double kelvin_voigt_time_s = 0.0;  ///< eta / E_unrelaxed
  double softening_d = 0.0;  ///< first-load softening (GpsSoftening)

  bool operator==(const ViscoelasticSpec&) const = default;
};

struct ViscoelasticSetup {
  Mat6 unrelaxed_elasticity;  ///< what the GPS is built with
  GpsMechanisms gps;
  ConstantQFit shear_fit;
  std::optional<ConstantQFit> bulk_fit;  ///< none when the bulk is elastic or relaxes as the shear (bulk_q = shear_q)
  std::string table;  ///< the fitted mechanisms, for the user
};

/// D_reference: elasticity at the reference frequency (|M| of the deviatoric and volumetric parts).
/// Throws InputError naming `source` and the field for invalid values.
ViscoelasticSetup make_viscoelastic(const Mat6& D_reference, const ViscoelasticSpec& spec, const std::string& source = "viscoelasticity");

}  // namespace viscera::tissue
