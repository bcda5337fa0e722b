#include "viscera/lab/synthetic_data.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <functional>
#include <random>

namespace viscera::lab::test {

const char* effect_name(Effect e) {
  switch (e) {
    case Effect::none: return "none";
    case Effect::broadband_relaxation: return "broadband_relaxation";
    case Effect::strain_stiffening: return "strain_stiffening";
    case Effect::tension_compression_asymmetry: return "tension_compression_asymmetry";
    case Effect::first_load_softening: return "first_load_softening";
  }
  return "?";
}

namespace {

// A piecewise-linear strain (or stress) protocol: knots (t, value).
struct Protocol {
  std::vector<double> t, v;
  double at(double x) const {
    if (x <= t.front()) return v.front();
    for (std::size_t k = 1; k < t.size(); ++k)
      if (x <= t[k]) return v[k - 1] + (v[k] - v[k - 1]) * (x - t[k - 1]) / (t[k] - t[k - 1]);
    return v.back();
  }
  double rate(double x) const {  // left derivative
    for (std::size_t k = 1; k < t.size(); ++k)
      if (x <= t[k]) return (v[k] - v[k - 1]) / (t[k] - t[k - 1]);
    return 0.0;
  }
};

// Elastic shape of the truth and its derivative, with the first-load history.
struct Shape {
  const Truth& tr;
  double peak_t = 0, peak_c = 0;
  double value(double e) const {
    double s = e;
    if (tr.effect == Effect::strain_stiffening)  // odd in shear: an isotropic solid's shear stress is
      s = tr.odd ? std::copysign(std::expm1(tr.stiffening_b * std::abs(e)) / tr.stiffening_b, e) : std::expm1(tr.stiffening_b * e) / tr.stiffening_b;
    if (tr.effect == Effect::tension_compression_asymmetry && e < 0) s *= tr.compression_ratio;
    if (tr.effect == Effect::first_load_softening) {
      const double peak = e >= 0 ? peak_t : peak_c;
      if (std::abs(e) < peak) s *= 1 - tr.softening_d * (1 - std::abs(e) / peak);
    }
    return s;
  }
  void advance(double e) {
    if (e >= 0)
      peak_t = std::max(peak_t, e);
    else
      peak_c = std::max(peak_c, -e);
  }
};

// Stress at the sample times under strain control. Kelvin-Voigt part from the shape and its
// exact left derivative; the relaxation spectrum (linear in strain, effect broadband only) by the
// closed-form integral of exp(-(t-u)/tau) d eps(u) over each linear piece.
std::vector<double> stress_under_strain(const Truth& tr, const Protocol& p, const std::vector<double>& times) {
  std::vector<double> out;
  Shape shape{tr};
  double last = 0.0;
  for (double t : times) {
    // Walk the shape's history (first-load peaks) finely up to t.
    for (double u = last; u < t; u += 1e-3) shape.advance(p.at(u));
    last = t;
    const double e = p.at(t), h = 1e-7;
    const double s = shape.value(e);
    const double ds = (shape.value(e) - shape.value(e - h * p.rate(t))) / h;  // ds/de * de/dt (left)
    double sigma = tr.modulus_pa * (s + tr.tau_s * ds);
    if (tr.effect == Effect::broadband_relaxation)
      for (int l = 0; l < 2; ++l) {
        double acc = 0.0;
        for (std::size_t k = 1; k < p.t.size() && p.t[k - 1] < t; ++k) {
          const double a = p.t[k - 1], b = std::min(p.t[k], t), slope = (p.v[k] - p.v[k - 1]) / (p.t[k] - p.t[k - 1]);
          const double tau = tr.spectrum_tau_s[l];
          acc += slope * tau * (std::exp(-(t - b) / tau) - std::exp(-(t - a) / tau));
        }
        sigma += tr.spectrum_pa[l] * acc;
      }
    if (tr.power_pa > 0) {  // closed form of the integral of (1 + (t-u)/tau0)^-alpha over each linear piece
      double acc = 0.0;
      const double tau0 = tr.power_tau0_s, q = 1.0 - tr.power_alpha;
      for (std::size_t k = 1; k < p.t.size() && p.t[k - 1] < t; ++k) {
        const double a = p.t[k - 1], b = std::min(p.t[k], t), slope = (p.v[k] - p.v[k - 1]) / (p.t[k] - p.t[k - 1]);
        acc += slope * tau0 / q * (std::pow(1 + (t - a) / tau0, q) - std::pow(1 + (t - b) / tau0, q));
      }
      sigma += tr.power_pa * acc;
    }
    out.push_back(sigma);
  }
  return out;
}

// Strain under stress control: Kelvin-Voigt with shape, E (s(e) + tau s'(e) de/dt) = sigma(t),
// integrated with RK4 at a fine step (the first-load effect is not used with creep tests).
std::vector<double> strain_under_stress(const Truth& tr, const Protocol& p, const std::vector<double>& times) {
  Shape shape{tr};
  const auto rhs = [&](double t, double e) {
    const double h = 1e-7;
    const double slope = (shape.value(e + h) - shape.value(e - h)) / (2 * h);
    return (p.at(t) / tr.modulus_pa - shape.value(e)) / (tr.tau_s * slope);
  };
  std::vector<double> out;
  double t = 0.0, e = 0.0;
  for (double target : times) {
    const int n = 200;
    const double dt = (target - t) / n;
    for (int k = 0; k < n && dt > 0; ++k) {
      const double k1 = rhs(t, e), k2 = rhs(t + dt / 2, e + dt / 2 * k1), k3 = rhs(t + dt / 2, e + dt / 2 * k2), k4 = rhs(t + dt, e + dt * k3);
      e += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += dt;
    }
    out.push_back(e);
  }
  return out;
}

// Sample times: dense during the first `ramp` seconds after each knot, sparse in holds.
std::vector<double> sample_times(const Protocol& p, std::mt19937_64& rng) {
  std::vector<double> times;
  std::uniform_real_distribution<double> jitter(0.2, 0.8);
  const double end = p.t.back();
  double t = 0.0;
  while (t < end) {
    double dt = 0.5;
    for (std::size_t k = 1; k < p.t.size(); ++k)
      if (t >= p.t[k - 1] && t < p.t[k] && p.v[k] != p.v[k - 1]) dt = std::min(dt, (p.t[k] - p.t[k - 1]) / 25);
    for (double knot : p.t)
      if (t > knot && t < knot + 3.0) dt = std::min(dt, 0.1 + (t - knot) * 0.2);
    t += dt * (0.5 + jitter(rng));
    if (t < end) times.push_back(t);
  }
  return times;
}

Protocol ramp_hold(double strain, double ramp_s, double hold_s) { return {{0.0, ramp_s, ramp_s + hold_s}, {0.0, strain, strain}}; }

Protocol cycles(double amplitude, double period_s, int n, bool both_signs) {
  Protocol p{{0.0}, {0.0}};
  for (int c = 0; c < n; ++c) {
    const double t0 = c * period_s;
    p.t.push_back(t0 + period_s / 4);
    p.v.push_back(amplitude);
    p.t.push_back(t0 + 3 * period_s / 4);
    p.v.push_back(both_signs ? -amplitude : 0.0);
    p.t.push_back(t0 + period_s);
    p.v.push_back(0.0);
  }
  return p;
}

}  // namespace

namespace {
Truth write_dataset_of(unsigned seed, const std::string& folder, bool power_law);
}  // namespace

Truth write_synthetic_dataset(unsigned seed, const std::string& folder) { return write_dataset_of(seed, folder, false); }
Truth write_power_law_dataset(unsigned seed, const std::string& folder) { return write_dataset_of(seed, folder, true); }

namespace {
Truth write_dataset_of(unsigned seed, const std::string& folder, bool power_law) {
  std::mt19937_64 rng(seed * 7919u + 17u + (power_law ? 1000003u : 0u));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto between = [&](double a, double b) { return a + (b - a) * u(rng); };
  const auto log_between = [&](double a, double b) { return std::exp(between(std::log(a), std::log(b))); };
  Truth tr;
  tr.effect = power_law ? Effect::broadband_relaxation : static_cast<Effect>(seed % 5);
  tr.modulus_pa = log_between(2e3, 50e3);
  tr.tau_s = log_between(0.02, 0.5);
  const double strain = between(0.06, 0.15);
  switch (tr.effect) {
    case Effect::broadband_relaxation:
      if (power_law) {
        tr.power_pa = tr.modulus_pa * between(0.5, 1.5);
        tr.power_alpha = between(0.1, 0.4);
        tr.power_tau0_s = log_between(0.01, 0.1);
        break;
      }
      for (int l = 0; l < 2; ++l) {
        tr.spectrum_pa[l] = tr.modulus_pa * between(0.3, 1.0);
        tr.spectrum_tau_s[l] = l == 0 ? log_between(0.3, 3.0) : log_between(5.0, 40.0);
      }
      break;
    case Effect::strain_stiffening: tr.stiffening_b = between(8.0, 20.0) / (strain / 0.1); break;
    case Effect::tension_compression_asymmetry: tr.compression_ratio = u(rng) < 0.5 ? between(0.3, 0.6) : between(1.7, 3.0); break;
    case Effect::first_load_softening: tr.softening_d = between(0.3, 0.6); break;
    case Effect::none: break;
  }
  Dataset d;
  d.name = std::string(power_law ? "synthetic power-law seed " : "synthetic seed ") + std::to_string(seed);
  // Simple shear in every other seed, but never for asymmetry, which an isotropic solid shows only
  // under uniaxial load (its shear stress is odd in the shear strain); stiffening in shear is odd.
  d.mode = seed % 2 || tr.effect == Effect::tension_compression_asymmetry ? Mode::uniaxial : Mode::simple_shear;
  tr.odd = d.mode == Mode::simple_shear;
  d.specimen = {0.01, 0.01, 0.003, 1050};
  // Each test on an untouched specimen: the truth's first-load history starts afresh in each.
  d.history = History::reset;
  // Protocols: ramp-holds at two rates in tension and one in compression, cycles at two rates in
  // tension and compression, and a creep test.
  const double slow = between(3.0, 8.0), fast = between(0.2, 0.6);
  struct Spec {
    std::string file;
    Protocol p;
    Control control;
  };
  const std::vector<Spec> specs = {
      {"ramp_hold_fast.csv", ramp_hold(strain, fast, 30.0), Control::strain},
      {"ramp_hold_slow.csv", ramp_hold(strain, slow, 30.0), Control::strain},
      {"ramp_hold_compression.csv", ramp_hold(-strain, fast * 2, 30.0), Control::strain},
      {"cycles_fast.csv", cycles(strain, between(1.0, 3.0), 3, true), Control::strain},
      {"cycles_slow.csv", cycles(strain, between(6.0, 12.0), 3, true), Control::strain},
  };
  double peak = 0;
  for (const auto& s : specs)
    for (double v : stress_under_strain(tr, s.p, sample_times(s.p, rng))) peak = std::max(peak, std::abs(v));
  tr.noise_pa = peak * between(0.005, 0.02);
  std::normal_distribution<double> noise(0.0, tr.noise_pa);
  for (const auto& s : specs) {
    TestData t;
    t.file = s.file;
    t.control = s.control;
    t.time_s = sample_times(s.p, rng);
    t.strain.clear();
    for (double x : t.time_s) t.strain.push_back(s.p.at(x));
    t.stress_pa = stress_under_strain(tr, s.p, t.time_s);
    for (double& v : t.stress_pa) v += noise(rng);
    t.stress_sd_pa.assign(t.time_s.size(), tr.noise_pa);
    d.tests.push_back(t);
  }
  if (tr.effect != Effect::first_load_softening && tr.effect != Effect::broadband_relaxation) {
    // Creep: stress ramped in 0.5 s to the level of the fast ramp's peak, held 20 s.
    TestData t;
    t.file = "creep.csv";
    t.control = Control::stress;
    const double level = 0.5 * tr.modulus_pa * strain;
    const Protocol p = ramp_hold(level, 0.5, 20.0);
    t.time_s = sample_times(p, rng);
    for (double x : t.time_s) t.stress_pa.push_back(p.at(x));
    t.strain = strain_under_stress(tr, p, t.time_s);
    std::normal_distribution<double> strain_noise(0.0, 0.002 * strain);
    for (double& e : t.strain) e += strain_noise(rng);
    d.tests.push_back(t);
  }
  write_dataset(d, folder);
  return tr;
}
}  // namespace

}  // namespace viscera::lab::test
