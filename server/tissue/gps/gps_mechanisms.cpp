#include "viscera/tissue/gps/gps_mechanisms.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <stdexcept>

namespace viscera::tissue {

namespace {
bool finite_at_least_zero(double v) { return std::isfinite(v) && v >= 0; }
}  // namespace

void GpsViscous::validate() const {
  if (mechanisms() > kMaxMechanisms) throw std::invalid_argument("GPS viscous part: at most 8 relaxation mechanisms");
  if (shear_weight.size() != mechanisms() || (!bulk_weight.empty() && bulk_weight.size() != mechanisms()))
    throw std::invalid_argument("GPS viscous part: one shear (and bulk) weight per relaxation frequency expected");
  for (std::size_t l = 0; l < mechanisms(); ++l)
    if (!(std::isfinite(omega_rad_s[l]) && omega_rad_s[l] > 0) || !std::isfinite(shear_weight[l]) || !std::isfinite(bulk(l)))
      throw std::invalid_argument("GPS viscous part: relaxation frequencies must be positive and weights finite");
  if (!finite_at_least_zero(kelvin_voigt_time_s)) throw std::invalid_argument("GPS viscous part: the Kelvin-Voigt time must be >= 0");
}

void GpsStiffening::validate() const {
  if (!finite_at_least_zero(b)) throw std::invalid_argument("GPS stiffening: Fung's B must be >= 0");
  if (shape != StiffeningShape::exponential && form != Form::energy)
    throw std::invalid_argument("GPS stiffening: the odd shapes exist in the energy form only");
}

void GpsAsymmetry::validate() const {
  if (!(std::isfinite(compression_ratio) && compression_ratio > 0))
    throw std::invalid_argument("GPS asymmetry: the compression ratio must be positive");
}

void GpsSoftening::validate() const {
  if (!(d >= 0 && d < 1)) throw std::invalid_argument("GPS softening: first-load softening must lie in [0, 1)");
}

void GpsMechanisms::validate() const {
  viscous.validate();
  stiffening.validate();
  asymmetry.validate();
  softening.validate();
  if (asymmetry.active() && stiffening.form != GpsStiffening::Form::energy)
    throw std::invalid_argument("GPS asymmetry needs the stiffening's energy form");
  if (energy_map() && viscous.bulk_differs())
    throw std::invalid_argument("GPS stiffening in energy form relaxes the whole tension: bulk and shear weights must agree");
}

}  // namespace viscera::tissue
