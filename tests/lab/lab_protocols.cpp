#include "lab_protocols.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace viscera::lab::test {

namespace {

// A piecewise-linear command: knots (t, v), constant after the last knot.
struct Command {
  std::vector<double> t, v;
  void to(double duration_s, double value) {
    t.push_back(t.back() + duration_s);
    v.push_back(value);
  }
  std::size_t piece(double x) const {  // index k of the piece [t[k-1], t[k]) holding x; size() after the end
    std::size_t k = 1;
    while (k < t.size() && x >= t[k]) ++k;
    return k;
  }
  double at(double x) const {
    const std::size_t k = piece(x);
    if (k >= t.size()) return v.back();
    return v[k - 1] + slope(k) * (x - t[k - 1]);
  }
  double slope(std::size_t k) const { return k >= t.size() ? 0.0 : (v[k] - v[k - 1]) / (t[k] - t[k - 1]); }
  double end() const { return t.back(); }
};

// Non-uniform sampling as a logger set to "dense at changes" writes it: 1 ms after every knot,
// each interval 8% longer than the last, at most 50 ms; never closer than 0.2 ms to a knot.
std::vector<double> sample_times(const Command& c, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> jitter(0.9, 1.1);
  std::vector<double> out;
  double t = 0.4e-3, dt = 1e-3;
  std::size_t last_piece = c.piece(t);
  while (t < c.end()) {
    out.push_back(t);
    dt = std::min(dt * 1.08, 0.05) * jitter(rng);
    double next = t + dt;
    const std::size_t p = c.piece(next);
    if (p != last_piece) {  // crossed a knot: restart dense just after it
      const double knot = c.t[std::min(p, c.t.size()) - 1];
      next = std::max(next, knot + 0.2e-3);
      next = std::min(next, knot + 1e-3);
      dt = 1e-3;
      last_piece = c.piece(next);
    }
    t = next;
  }
  return out;
}

Command ramp_hold(double strain, double ramp_s, double hold_s) {
  Command c{{0.0}, {0.0}};
  c.to(ramp_s, strain);
  c.to(hold_s, strain);
  return c;
}

// Triangles through tension and compression, amplitude growing by thirds.
Command growing_cycles(double amplitude, double period_s) {
  Command c{{0.0}, {0.0}};
  for (int k = 1; k <= 3; ++k) {
    const double a = amplitude * k / 3.0;
    c.to(period_s / 4, a);
    c.to(period_s / 2, -a);
    c.to(period_s / 4, 0.0);
  }
  c.to(2.0, 0.0);
  return c;
}

}  // namespace

KelvinVoigtTruth write_kelvin_voigt_lab_dataset(unsigned seed, const std::string& folder) {
  std::mt19937_64 rng(0x5eed0000ull + seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto between = [&](double a, double b) { return a + (b - a) * u(rng); };
  const auto log_between = [&](double a, double b) { return std::exp(between(std::log(a), std::log(b))); };
  KelvinVoigtTruth tr;
  tr.modulus_pa = log_between(1e3, 100e3);
  const double tau = log_between(0.005, 0.05);
  tr.viscosity_pa_s = tr.modulus_pa * tau;
  const double strain = between(0.05, 0.2);

  Dataset d;
  d.name = "Kelvin-Voigt truth, seed " + std::to_string(seed);
  d.mode = seed % 2 ? Mode::uniaxial : Mode::simple_shear;
  d.specimen = {between(0.005, 0.03), between(0.005, 0.02), between(0.001, 0.005), between(1000, 1100)};

  struct Spec {
    const char* file;
    Command c;
  };
  const std::vector<Spec> strain_tests = {
      {"ramp_0.05s.csv", ramp_hold(strain, 0.05, between(5, 15))},
      {"ramp_medium.csv", ramp_hold(strain, between(0.3, 1.0), between(5, 15))},
      {"ramp_slow.csv", ramp_hold(strain, between(3, 10), between(5, 15))},
      {"ramp_compression.csv", ramp_hold(-strain * between(0.5, 1.0), between(0.1, 1.0), between(5, 15))},
      {"cycles_growing.csv", growing_cycles(strain, between(1.0, 4.0))},
  };
  const auto stress_at = [&](const Command& c, double t) { return tr.modulus_pa * c.at(t) + tr.viscosity_pa_s * c.slope(c.piece(t)); };
  std::vector<std::vector<double>> times;
  double peak = 0;
  for (const auto& s : strain_tests) {
    times.push_back(sample_times(s.c, rng));
    for (double t : times.back()) peak = std::max(peak, std::abs(stress_at(s.c, t)));
  }
  tr.stress_noise_pa = peak * between(0.005, 0.02);
  std::normal_distribution<double> stress_noise(0.0, tr.stress_noise_pa);
  for (std::size_t k = 0; k < strain_tests.size(); ++k) {
    TestData t;
    t.file = strain_tests[k].file;
    t.control = Control::strain;
    t.time_s = times[k];
    for (double x : t.time_s) {
      t.strain.push_back(strain_tests[k].c.at(x));
      t.stress_pa.push_back(stress_at(strain_tests[k].c, x) + stress_noise(rng));
    }
    t.stress_sd_pa.assign(t.time_s.size(), tr.stress_noise_pa);
    d.tests.push_back(std::move(t));
  }

  // Creep and recovery: stress ramped in 0.05 s, held, released in 0.05 s, recovery.
  const double level = tr.modulus_pa * strain * between(0.3, 0.8);
  Command c{{0.0}, {0.0}};
  c.to(0.05, level);
  c.to(between(5, 15), level);
  c.to(0.05, 0.0);
  c.to(between(5, 15), 0.0);
  TestData creep;
  creep.file = "creep_recovery.csv";
  creep.control = Control::stress;
  creep.time_s = sample_times(c, rng);
  // Exact strain of eta eps' + E eps = sigma on each linear piece of sigma, knot to knot.
  double e = 0.0, t0 = 0.0;
  std::size_t piece = 1;
  const auto advance = [&](double t1) {  // within one piece: sigma = sigma(t0) + m (t - t0)
    const double m = c.slope(piece), s0 = c.at(t0), dt = t1 - t0;
    const double particular0 = s0 / tr.modulus_pa - m * tau / tr.modulus_pa;
    const double particular1 = (s0 + m * dt) / tr.modulus_pa - m * tau / tr.modulus_pa;
    e = particular1 + (e - particular0) * std::exp(-dt / tau);
    t0 = t1;
  };
  std::vector<double> exact;
  for (double t : creep.time_s) {
    while (piece < c.t.size() && c.t[piece] <= t) {
      advance(c.t[piece]);
      ++piece;
    }
    advance(t);
    exact.push_back(e);
  }
  tr.strain_noise = *std::max_element(exact.begin(), exact.end()) * between(0.005, 0.02);
  tr.creep_stress_noise_pa = level * 0.005;
  std::normal_distribution<double> strain_noise(0.0, tr.strain_noise), load_noise(0.0, tr.creep_stress_noise_pa);
  for (std::size_t k = 0; k < exact.size(); ++k) {
    creep.strain.push_back(exact[k] + strain_noise(rng));
    creep.stress_pa.push_back(c.at(creep.time_s[k]) + load_noise(rng));
  }
  creep.stress_sd_pa.assign(creep.time_s.size(), tr.creep_stress_noise_pa);
  d.tests.push_back(std::move(creep));
  write_dataset(d, folder);
  return tr;
}

}  // namespace viscera::lab::test
