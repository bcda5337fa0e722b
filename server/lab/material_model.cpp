#include "viscera/lab/material_model.hpp"

#include <algorithm>
#include <cmath>

#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"

namespace viscera::lab {

const char* name(Mechanism m) {
  switch (m) {
    case Mechanism::broadband_relaxation: return "broadband_relaxation";
    case Mechanism::strain_stiffening: return "strain_stiffening";
    case Mechanism::tension_compression_asymmetry: return "tension_compression_asymmetry";
    case Mechanism::first_load_softening: return "first_load_softening";
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
  return n;
}

std::vector<double> elastic_shape(const MaterialModel& m, const std::vector<double>& strain) {
  std::vector<double> s(strain.size());
  double max_t = 0.0, max_c = 0.0;  // previous extremes in tension and compression
  for (std::size_t k = 0; k < strain.size(); ++k) {
    const double e = strain[k];
    double v = e;
    if (m.has(Mechanism::strain_stiffening) && m.stiffening_b > 0) v = std::expm1(m.stiffening_b * e) / m.stiffening_b;
    if (m.has(Mechanism::tension_compression_asymmetry) && e < 0) v *= m.compression_ratio;
    if (m.has(Mechanism::first_load_softening)) {
      const double peak = e >= 0 ? max_t : max_c;
      const double a = std::abs(e);
      if (a < peak) v *= 1.0 - m.softening_d * (1.0 - a / peak);
      if (e >= 0)
        max_t = std::max(max_t, a);
      else
        max_c = std::max(max_c, a);
    }
    s[k] = v;
  }
  return s;
}

Eigen::MatrixXd basis(const MaterialModel& m, const TestData& t) {
  const auto n = static_cast<Eigen::Index>(t.time_s.size());
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  Eigen::MatrixXd A(n, static_cast<Eigen::Index>(2 + L));
  const std::vector<double> s = elastic_shape(m, t.strain);
  std::vector<double> h(L, 0.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    A(k, 0) = s[uk];
    A(k, 1) = k == 0 ? 0.0 : (s[uk] - s[uk - 1]) / (t.time_s[uk] - t.time_s[uk - 1]);
    for (std::size_t l = 0; l < L; ++l) {
      if (k > 0) {
        // Exact for s linear over the interval: h <- e h + (ds/dt) tau (1 - e).
        const double dt = t.time_s[uk] - t.time_s[uk - 1], tau = m.relaxation_time_s[l];
        const tissue::MemoryStep step = tissue::MemoryStep::make(1.0 / tau, dt);
        h[l] = step.e * h[l] + (s[uk] - s[uk - 1]) / dt * tau * step.a;
      }
      A(k, static_cast<Eigen::Index>(2 + l)) = h[l];
    }
  }
  return A;
}

namespace {
Eigen::VectorXd coefficients(const MaterialModel& m) {
  const std::size_t L = m.has(Mechanism::broadband_relaxation) ? m.relaxation_time_s.size() : 0;
  Eigen::VectorXd c(static_cast<Eigen::Index>(2 + L));
  c(0) = m.modulus_pa;
  c(1) = m.viscosity_pa_s;
  for (std::size_t l = 0; l < L; ++l) c(static_cast<Eigen::Index>(2 + l)) = m.relaxation_modulus_pa[l];
  return c;
}
}  // namespace

std::vector<double> predict_stress(const MaterialModel& m, const TestData& t) {
  const Eigen::VectorXd y = basis(m, t) * coefficients(m);
  return {y.data(), y.data() + y.size()};
}

std::vector<double> predict_strain(const MaterialModel& m, const TestData& t) {
  // Sample by sample: find eps_k with sigma_k(eps_k | history) = measured stress; sigma is
  // increasing in eps_k, so bisection on a bracket is robust for every mechanism.
  std::vector<double> eps;
  TestData probe = t;
  for (std::size_t k = 0; k < t.time_s.size(); ++k) {
    probe.time_s.assign(t.time_s.begin(), t.time_s.begin() + static_cast<long>(k) + 1);
    probe.stress_pa.assign(t.stress_pa.begin(), t.stress_pa.begin() + static_cast<long>(k) + 1);
    probe.strain = eps;
    probe.strain.push_back(0.0);
    const auto stress_at = [&](double e) {
      probe.strain.back() = e;
      return predict_stress(m, probe).back();
    };
    double lo = -2.0, hi = 2.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (stress_at(mid) < t.stress_pa[k] ? lo : hi) = mid;
    }
    eps.push_back(0.5 * (lo + hi));
  }
  return eps;
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
