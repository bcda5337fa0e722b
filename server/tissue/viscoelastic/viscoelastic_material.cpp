#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <sstream>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/material/elasticity.hpp"

namespace viscera::tissue {

using common::InputError;

namespace {
Mat6 volumetric_part(const Mat6& D) {
  Vec6 m;
  m << 1, 1, 1, 0, 0, 0;
  return reuss_bulk_modulus(D) * m * m.transpose();
}
/// The spectrum as stated: D is the unrelaxed elasticity, each weight the share of it that relaxes
/// with its time, in shear and bulk alike (the whole elastic tension relaxes, as the lab's law).
ViscoelasticSetup relaxation_spectrum(const Mat6& D, const ViscoelasticSpec& spec, const std::string& source, ViscoelasticSetup& out) {
  const auto& tau = spec.relaxation_times_s;
  const auto& w = spec.relaxation_weights;
  if (tau.size() != w.size())
    throw InputError(source, 0, "relaxation_weights", std::to_string(w.size()) + " weights for " + std::to_string(tau.size()) + " relaxation times");
  if (tau.size() > GpsViscous::kMaxMechanisms)
    throw InputError(source, 0, "relaxation_times_s", std::to_string(tau.size()) + " times: at most " + std::to_string(GpsViscous::kMaxMechanisms));
  double sum = 0.0;
  for (std::size_t l = 0; l < tau.size(); ++l) {
    if (!(tau[l] > 0) || !std::isfinite(tau[l]))
      throw InputError(source, 0, "relaxation_times_s[" + std::to_string(l) + "]", std::to_string(tau[l]) + " must be a positive number");
    if (!(w[l] >= 0) || !std::isfinite(w[l]))
      throw InputError(source, 0, "relaxation_weights[" + std::to_string(l) + "]", std::to_string(w[l]) + " must be >= 0");
    sum += w[l];
  }
  if (!(sum < 1.0))
    throw InputError(source, 0, "relaxation_weights",
                     "sum to " + std::to_string(sum) + ": the relaxed modulus would be <= 0 (the sum must be below 1)");
  if (!(spec.kelvin_voigt_time_s >= 0) || !std::isfinite(spec.kelvin_voigt_time_s))
    throw InputError(source, 0, "kelvin_voigt_time_s", std::to_string(spec.kelvin_voigt_time_s) + " must be >= 0");
  if (!(spec.softening_d >= 0 && spec.softening_d < 1))
    throw InputError(source, 0, "softening_d", std::to_string(spec.softening_d) + " must lie in [0, 1)");
  std::ostringstream table;
  table << "relaxation spectrum (unrelaxed elasticity as given; shear and bulk relax alike):\n";
  for (std::size_t l = 0; l < tau.size(); ++l) {
    if (w[l] <= 0) continue;
    out.gps.viscous.omega_rad_s.push_back(1.0 / tau[l]);
    out.gps.viscous.shear_weight.push_back(w[l]);
    table << "  tau " << tau[l] << " s: weight " << w[l] << "\n";
  }
  out.gps.viscous.bulk_weight = out.gps.viscous.shear_weight;
  out.gps.viscous.kelvin_voigt_time_s = spec.kelvin_voigt_time_s;
  out.gps.softening.d = spec.softening_d;
  table << "  relaxed share " << 1.0 - sum << ", Kelvin-Voigt time " << spec.kelvin_voigt_time_s << " s";
  if (spec.softening_d > 0) table << ", first-load softening d = " << spec.softening_d;
  table << "\n";
  out.unrelaxed_elasticity = D;
  out.table = table.str();
  return out;
}

}  // namespace

ViscoelasticSetup make_viscoelastic(const Mat6& D, const ViscoelasticSpec& spec, const std::string& source) {
  if (!(spec.shear_q > 0) || !std::isfinite(spec.shear_q))
    throw InputError(source, 0, "shear_q", std::to_string(spec.shear_q) + " must be a positive number");
  if (spec.bulk_q && (!(*spec.bulk_q > 0) || !std::isfinite(*spec.bulk_q)))
    throw InputError(source, 0, "bulk_q", std::to_string(*spec.bulk_q) + " must be a positive number (or absent)");
  if (!(spec.qlv_stiffening >= 0) || !std::isfinite(spec.qlv_stiffening))
    throw InputError(source, 0, "qlv_stiffening", std::to_string(spec.qlv_stiffening) + " must be >= 0");
  if (!(spec.reference_frequency_hz > 0))
    throw InputError(source, 0, "reference_frequency_hz", std::to_string(spec.reference_frequency_hz) + " must be positive");
  if (!(spec.compression_ratio > 0) || !std::isfinite(spec.compression_ratio))
    throw InputError(source, 0, "compression_ratio", std::to_string(spec.compression_ratio) + " must be a positive number");
  if (spec.compression_ratio != 1.0 && spec.qlv_form != GpsStiffening::Form::energy)
    throw InputError(source, 0, "compression_ratio", std::to_string(spec.compression_ratio) + " needs \"qlv_form\": \"energy\"");
  if (spec.qlv_form == GpsStiffening::Form::energy && spec.model == ViscoelasticSpec::Model::constant_q &&
      (spec.qlv_stiffening > 0 || spec.compression_ratio != 1.0) && spec.bulk_q != spec.shear_q)
    throw InputError(source, 0, "qlv_form",
                     "\"energy\" relaxes the whole elastic tension, so it needs bulk_q equal to shear_q (" +
                         (spec.bulk_q ? std::to_string(*spec.bulk_q) : std::string("absent")) + " against " + std::to_string(spec.shear_q) + ")");
  if (spec.qlv_shape != StiffeningShape::exponential && spec.qlv_form != GpsStiffening::Form::energy)
    throw InputError(source, 0, "qlv_shape", "an odd shape needs \"qlv_form\": \"energy\"");
  ViscoelasticSetup out;
  out.gps.stiffening = {spec.qlv_stiffening, spec.qlv_form, spec.qlv_shape};
  out.gps.asymmetry.compression_ratio = spec.compression_ratio;
  if (spec.model == ViscoelasticSpec::Model::relaxation_spectrum) return relaxation_spectrum(D, spec, source, out);
  const Mat6 D_vol = volumetric_part(D), D_dev = D - D_vol;
  const double w_ref = 2 * M_PI * spec.reference_frequency_hz;
  if (spec.model == ViscoelasticSpec::Model::kelvin_voigt) {
    // One relaxation time tau with Q(w_ref) = 1 / (w_ref tau), and |M(w_ref)| kept: E_kv = |M| / sqrt(1 + 1/Q^2).
    out.gps.viscous.kelvin_voigt_time_s = 1.0 / (spec.shear_q * w_ref);
    out.unrelaxed_elasticity = D / std::sqrt(1.0 + 1.0 / (spec.shear_q * spec.shear_q));
    std::ostringstream s;
    s << "Kelvin-Voigt: relaxation time " << out.gps.viscous.kelvin_voigt_time_s << " s (Q = " << spec.shear_q << " at "
      << spec.reference_frequency_hz << " Hz only; Q(f) = Q f_ref / f)\n";
    out.table = s.str();
    return out;
  }
  // Targets in the material's own moduli (shear modulus D_xy,xy; Reuss bulk modulus) so the table
  // shows pascals; the factors M_U / |M(w_ref)| scale the deviatoric and volumetric parts of D.
  ConstantQTarget shear{spec.shear_q, spec.band_low_hz, spec.band_high_hz, spec.mechanisms, D(5, 5), spec.reference_frequency_hz};
  out.shear_fit = fit_constant_q(shear, source);
  const double shear_factor = out.shear_fit.solids.unrelaxed_modulus_pa / D(5, 5);
  out.gps.viscous.omega_rad_s = out.shear_fit.solids.omega_rad_s;
  out.gps.viscous.shear_weight = out.shear_fit.solids.weight;
  double bulk_factor = 1.0;
  const bool bulk_as_shear = spec.bulk_q && *spec.bulk_q == spec.shear_q;
  if (bulk_as_shear) {  // the same dimensionless fit: the weights are the shear's exactly
    out.gps.viscous.bulk_weight = out.gps.viscous.shear_weight;
    bulk_factor = shear_factor;
  } else if (spec.bulk_q) {
    ConstantQTarget bulk = shear;
    bulk.q = *spec.bulk_q;
    bulk.modulus_pa = reuss_bulk_modulus(D);
    bulk.fixed_frequencies_rad_s = out.gps.viscous.omega_rad_s;
    out.bulk_fit = fit_constant_q(bulk, source);
    out.gps.viscous.bulk_weight = out.bulk_fit->solids.weight;
    bulk_factor = out.bulk_fit->solids.unrelaxed_modulus_pa / bulk.modulus_pa;
  } else {
    out.gps.viscous.bulk_weight.assign(out.gps.viscous.omega_rad_s.size(), 0.0);
  }
  out.unrelaxed_elasticity = shear_factor * D_dev + bulk_factor * D_vol;
  out.table = "shear: " + describe(out.shear_fit, shear);
  if (bulk_as_shear) {
    out.table += "bulk: relaxes as the shear (the same Q, frequencies and weights)\n";
  } else if (out.bulk_fit) {
    ConstantQTarget bulk = shear;
    bulk.q = *spec.bulk_q;
    bulk.modulus_pa = reuss_bulk_modulus(D);
    out.table += "bulk (same relaxation frequencies): " + describe(*out.bulk_fit, bulk);
  } else {
    out.table += "bulk: elastic (no bulk relaxation)\n";
  }
  return out;
}

}  // namespace viscera::tissue
