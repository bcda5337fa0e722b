#include "viscera/lab/material_model.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include "viscera/lab/command_path.hpp"
#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"

namespace viscera::lab {

const char* name(Mechanism m) {
  switch (m) {
    case Mechanism::broadband_relaxation: return "broadband_relaxation";
    case Mechanism::strain_stiffening: return "strain_stiffening";
    case Mechanism::tension_compression_asymmetry: return "tension_compression_asymmetry";
    case Mechanism::first_load_softening: return "first_load_softening";
    case Mechanism::contact_take_up: return "contact_take_up";
  }
  return "?";
}

bool parse_mechanism(const std::string& s, Mechanism* out) {
  for (Mechanism m : kMechanisms)
    if (s == name(m)) {
      *out = m;
      return true;
    }
  return false;
}

const char* name(StiffeningForm f) {
  switch (f) {
    case StiffeningForm::exponential: return "exponential";
    case StiffeningForm::odd_exponential: return "odd_exponential";
    case StiffeningForm::odd_polynomial: return "odd_polynomial";
    case StiffeningForm::ogden: return "ogden";
  }
  return "?";
}

bool parse_stiffening_form(const std::string& s, StiffeningForm* out) {
  for (StiffeningForm f : {StiffeningForm::exponential, StiffeningForm::odd_exponential, StiffeningForm::odd_polynomial, StiffeningForm::ogden})
    if (s == name(f)) {
      *out = f;
      return true;
    }
  return false;
}

std::string MaterialModel::describe() const {
  std::string s = "kelvin_voigt_linear";
  for (Mechanism m : kMechanisms)
    if (has(m)) s += std::string(" + ") + name(m);
  return s;
}

int MaterialModel::parameter_count() const {
  int n = 2 + (has(Mechanism::broadband_relaxation) ? static_cast<int>(relaxation_time_s.size()) : 0);
  for (Mechanism m : kMechanisms)
    if (has(m) && m != Mechanism::broadband_relaxation) ++n;
  if (has(Mechanism::first_load_softening) && history_carried) ++n;  // the kept fraction
  return n;
}

MaterialModel for_dataset(MaterialModel m, const Dataset& d) {
  m.odd_only = d.mode == Mode::simple_shear;
  m.platens = d.platens;
  m.history_carried = std::any_of(d.tests.begin(), d.tests.end(), [](const TestData& t) { return t.before_tension + t.before_compression > 0; });
  return m;
}

double specimen_strain(const MaterialModel& m, double e) {
  if (!m.has(Mechanism::contact_take_up)) return e;
  return std::min(0.0, e + m.contact_strain);
}

namespace {
// Ogden's one-term incompressible response with exponent a, normalised to slope 1 at rest:
// uniaxial nominal stress over 3 mu, or the simple-shear stress over mu (docs in the header).
double ogden_response(double a, double e, bool shear) {
  if (shear) {
    const double l = 0.5 * e + std::sqrt(1 + 0.25 * e * e);
    return 2 / a * (std::pow(l, a) - std::pow(l, -a)) / (l + 1 / l);
  }
  const double l = 1 + e;
  if (l <= 1e-6) return -1e300;  // a specimen compressed to nothing
  return 2 / (3 * a) * (std::pow(l, a - 1) - std::pow(l, -a / 2 - 1));
}
}  // namespace

double ElasticShape::value(double test_strain) const {
  const double e = specimen_strain(m, test_strain);
  double v = e;
  if (m.has(Mechanism::strain_stiffening) && m.stiffening_b > 0) {
    const double B = m.stiffening_b;
    switch (m.stiffening_form) {
      case StiffeningForm::exponential: v = std::expm1(B * e) / B; break;
      case StiffeningForm::odd_exponential: v = std::copysign(std::expm1(B * std::abs(e)) / B, e); break;
      case StiffeningForm::odd_polynomial: v = e * (1 + B * B * e * e / 6); break;
      case StiffeningForm::ogden: v = ogden_response(B, e, m.odd_only); break;
    }
  }
  if (m.has(Mechanism::tension_compression_asymmetry) && e < 0) v *= m.compression_ratio;
  if (m.has(Mechanism::first_load_softening)) {
    const double peak = e >= 0 ? max_tension : max_compression, a = std::abs(e);
    if (a < peak) v *= 1.0 - m.softening_d * (1.0 - a / peak);
  }
  return v;
}

void ElasticShape::advance(double test_strain) {
  const double e = specimen_strain(m, test_strain);
  if (e >= 0)
    max_tension = std::max(max_tension, e);
  else
    max_compression = std::max(max_compression, -e);
}

double ElasticShape::strain_for(double s) const {
  // value() is increasing in e for every mechanism (softening's factor keeps d < 1; flat over a
  // contact gap, where any strain in it will do).
  double lo = -1.0, hi = 1.0;
  while (value(lo) > s && lo > -1e6) lo *= 2;
  while (value(hi) < s && hi < 1e6) hi *= 2;
  for (int it = 0; it < 80 && hi - lo > 1e-15 * (std::abs(lo) + std::abs(hi)); ++it) {
    const double mid = 0.5 * (lo + hi);
    (value(mid) < s ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

ElasticShape shape_at_start(const MaterialModel& m, const TestData& t) {
  ElasticShape shape{m};
  const double kept = m.has(Mechanism::first_load_softening) ? m.softening_kept : 1.0;
  shape.advance(kept * t.before_tension);
  shape.advance(-kept * t.before_compression);
  return shape;
}

std::vector<double> elastic_shape(ElasticShape shape, const std::vector<double>& strain) {
  std::vector<double> s(strain.size());
  for (std::size_t k = 0; k < strain.size(); ++k) {
    s[k] = shape.value(strain[k]);
    shape.advance(strain[k]);
  }
  return s;
}

Eigen::MatrixXd basis(const MaterialModel& m, const TestData& t) {
  const auto n = static_cast<Eigen::Index>(t.time_s.size());
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  Eigen::MatrixXd A(n, static_cast<Eigen::Index>(2 + L));
  const CommandPath path = command_path(t.time_s, t.strain);
  const std::vector<double> s = elastic_shape(shape_at_start(m, t), path.value);
  std::vector<double> h(L, 0.0);
  std::size_t next = 0;  // the next sample's index
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (j > 0)
      for (std::size_t l = 0; l < L; ++l) {
        // Exact for s linear over the piece: h <- e h + (ds/dt) tau (1 - e).
        const double dt = path.time_s[j] - path.time_s[j - 1], tau = m.relaxation_time_s[l];
        const tissue::MemoryStep step = tissue::MemoryStep::make(1.0 / tau, dt);
        h[l] = step.e * h[l] + (s[j] - s[j - 1]) / dt * tau * step.a;
      }
    if (path.sample[next] != j) continue;
    const auto k = static_cast<Eigen::Index>(next++);
    A(k, 0) = s[j];
    A(k, 1) = j == 0 ? 0.0 : (s[j] - s[j - 1]) / (path.time_s[j] - path.time_s[j - 1]);
    for (std::size_t l = 0; l < L; ++l) A(k, static_cast<Eigen::Index>(2 + l)) = h[l];
  }
  return A;
}

Eigen::VectorXd linear_coefficients(const MaterialModel& m) {
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  Eigen::VectorXd c(static_cast<Eigen::Index>(2 + L));
  c(0) = m.modulus_pa;
  c(1) = m.viscosity_pa_s;
  for (std::size_t l = 0; l < L; ++l) c(static_cast<Eigen::Index>(2 + l)) = m.relaxation_modulus_pa[l];
  return c;
}

void set_linear_coefficients(MaterialModel& m, const Eigen::VectorXd& c) {
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  m.modulus_pa = c(0);
  m.viscosity_pa_s = c(1);
  m.relaxation_modulus_pa.assign(L, 0.0);
  for (std::size_t l = 0; l < L; ++l) m.relaxation_modulus_pa[l] = c(static_cast<Eigen::Index>(2 + l));
}

std::vector<double> predict_stress(const MaterialModel& m, const TestData& t) {
  Eigen::VectorXd y = basis(m, t) * linear_coefficients(m);
  if (m.platens) y = y.cwiseMin(0.0);
  return {y.data(), y.data() + y.size()};
}

std::vector<double> relaxation_times_for(const Dataset& d) {
  double shortest = 1e300, longest = 0.0;
  for (const auto& t : d.tests) {
    for (std::size_t k = 1; k < t.time_s.size(); ++k) shortest = std::min(shortest, t.time_s[k] - t.time_s[k - 1]);
    longest = std::max(longest, t.time_s.back() - t.time_s.front());
  }
  std::vector<double> taus;
  for (double e = std::floor(std::log10(std::max(shortest, 1e-4))); e <= std::ceil(std::log10(longest)); e += 1.0) taus.push_back(std::pow(10.0, e));
  return taus;
}

}  // namespace viscera::lab
