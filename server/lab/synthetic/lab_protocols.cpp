#include "viscera/lab/lab_protocols.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace viscera::lab::test {

const char* name(LabTruth t) {
  switch (t) {
    case LabTruth::none: return "none";
    case LabTruth::exponential_stiffening: return "exponential_stiffening";
    case LabTruth::polynomial_stiffening: return "polynomial_stiffening";
    case LabTruth::asymmetry: return "asymmetry";
    case LabTruth::softening: return "softening";
    case LabTruth::recovering_softening: return "recovering_softening";
    case LabTruth::broadband: return "broadband";
    case LabTruth::power_law: return "power_law";
    case LabTruth::broadband_and_stiffening: return "broadband_and_stiffening";
    case LabTruth::permanent_set: return "permanent_set";
    case LabTruth::instrument_drift: return "instrument_drift";
    case LabTruth::rate_thinning: return "rate_thinning";
    case LabTruth::grip_slip: return "grip_slip";
  }
  return "?";
}

std::vector<std::string> expected_causes(LabTruth t) {
  switch (t) {
    case LabTruth::none: return {};
    case LabTruth::exponential_stiffening:
    case LabTruth::polynomial_stiffening: return {"strain_stiffening"};
    case LabTruth::asymmetry: return {"tension_compression_asymmetry"};
    case LabTruth::softening:
    case LabTruth::recovering_softening: return {"first_load_softening"};
    case LabTruth::broadband:
    case LabTruth::power_law: return {"broadband_relaxation"};
    case LabTruth::broadband_and_stiffening: return {"broadband_relaxation", "strain_stiffening"};
    case LabTruth::permanent_set:
    case LabTruth::instrument_drift:
    case LabTruth::rate_thinning:
    case LabTruth::grip_slip: return {};  // none of the catalogue's: whatever is named helps only in part
  }
  return {};
}

bool names_expected_causes(LabTruth t, const std::vector<Mechanism>& causes) {
  const auto expected = expected_causes(t);
  if (expected.size() != causes.size()) return false;
  for (const auto& e : expected) {
    bool found = false;
    for (Mechanism m : causes) found |= e == name(m);
    if (!found) return false;
  }
  return true;
}

bool out_of_family(LabTruth t) {
  return t == LabTruth::polynomial_stiffening || t == LabTruth::recovering_softening || t == LabTruth::power_law || out_of_catalogue(t);
}

bool out_of_catalogue(LabTruth t) {
  return t == LabTruth::permanent_set || t == LabTruth::instrument_drift || t == LabTruth::rate_thinning || t == LabTruth::grip_slip;
}

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
      next = std::clamp(next, knot + 0.2e-3, knot + 1e-3);
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

// The truth's elastic law with its history (the largest |strain| seen on each side).
struct Elastic {
  const LabDatasetTruth& tr;
  double peak_tension = 0, peak_compression = 0;
  double plastic = 0;  // permanent_set: the plastic strain
  double slipped = 0;  // grip_slip: the strain lost in the grips (once)
  double value(double e) const {
    const double E = tr.modulus_pa, B = tr.stiffening_b;
    switch (tr.truth) {
      case LabTruth::permanent_set: return E * std::clamp(e - plastic, -tr.yield_strain, tr.yield_strain);
      case LabTruth::grip_slip: return E * (e - slipped);
      case LabTruth::exponential_stiffening:
      case LabTruth::broadband_and_stiffening:
        if (tr.mode == Mode::simple_shear) return (e < 0 ? -1.0 : 1.0) * E / B * std::expm1(B * std::abs(e));
        return E / B * std::expm1(B * e);
      case LabTruth::polynomial_stiffening: return E * e * (1 + B * B * e * e / 6);
      case LabTruth::asymmetry: return e < 0 ? tr.compression_ratio * E * e : E * e;
      case LabTruth::softening:
      case LabTruth::recovering_softening: {
        const double m = e >= 0 ? peak_tension : peak_compression;
        return std::abs(e) < m ? E * e * (1 - tr.softening_d * (1 - std::abs(e) / m)) : E * e;
      }
      default: return E * e;
    }
  }
  double slope(double e) const { return (value(e + 1e-8) - value(e - 1e-8)) / 2e-8; }
  // Moves the history over a time step h at strain e (recovery only for recovering softening).
  void advance(double e, double h) {
    if (tr.truth == LabTruth::permanent_set) plastic = std::clamp(plastic, e - tr.yield_strain, e + tr.yield_strain);
    if (tr.truth == LabTruth::grip_slip && slipped == 0 && std::abs(value(e)) > tr.slip_stress_pa) slipped = tr.slip_fraction * e;
    double& m = e >= 0 ? peak_tension : peak_compression;
    m = std::max(m, std::abs(e));
    if (tr.truth == LabTruth::recovering_softening && tr.recovery_s > 0) {
      // Each side's memory relaxes towards the strain now on that side (0 on the other side).
      const double decay = std::exp(-h / tr.recovery_s), on_tension = std::max(e, 0.0), on_compression = std::max(-e, 0.0);
      peak_tension = on_tension + (peak_tension - on_tension) * decay;
      peak_compression = on_compression + (peak_compression - on_compression) * decay;
    }
  }
};

// Stress at the sample times under strain control, the specimen's history in `f` (moved to the
// end of the command).
std::vector<double> stress_under_strain(const LabDatasetTruth& tr, Elastic& f, const Command& c, const std::vector<double>& times) {
  std::vector<double> out;
  double walked = 0.0;
  for (double t : times) {
    // The history, walked finely up to t.
    const double h = std::max((t - walked) / 50, 1e-6);
    for (double u = walked + h; u < t; u += h) f.advance(c.at(u), h);
    walked = t;
    const double rate = c.slope(c.piece(t));
    double sigma = f.value(c.at(t)) + tr.viscosity_pa_s * rate;
    if (tr.thinning_pa > 0) sigma += (rate < 0 ? -1.0 : 1.0) * tr.thinning_pa * std::pow(std::abs(rate) / tr.thinning_rate, tr.thinning_n);
    f.advance(c.at(t), 0.0);
    // Hereditary relaxation on the strain, each linear piece in closed form.
    for (std::size_t k = 1; k < c.t.size() && c.t[k - 1] < t; ++k) {
      const double a = c.t[k - 1], b = std::min(c.t[k], t), slope = c.slope(k);
      for (int l = 0; l < 2; ++l) {
        const double tau = tr.spectrum_tau_s[l];
        if (tr.spectrum_pa[l] > 0) sigma += tr.spectrum_pa[l] * slope * tau * (std::exp(-(t - b) / tau) - std::exp(-(t - a) / tau));
      }
      if (tr.power_pa > 0) {
        const double tau0 = tr.power_tau0_s, q = 1.0 - tr.power_alpha;
        sigma += tr.power_pa * slope * tau0 / q * (std::pow(1 + (t - a) / tau0, q) - std::pow(1 + (t - b) / tau0, q));
      }
    }
    out.push_back(sigma);
  }
  const double h = std::max((c.end() - walked) / 50, 1e-6);
  for (double u = walked + h; u < c.end(); u += h) f.advance(c.at(u), h);
  return out;
}

// Strain at the sample times under stress control: backward Euler at `substeps` per sample
// interval, Newton on the strain each step; relaxation terms h_l exact for a linear strain step.
std::vector<double> strain_under_stress(const LabDatasetTruth& tr, Elastic f, const Command& c, const std::vector<double>& times, int substeps) {
  double e = 0.0, t = 0.0, hl[2] = {0, 0};
  std::vector<double> out;
  for (double target : times) {
    const double h = (target - t) / substeps;
    for (int s = 0; s < substeps && h > 0; ++s) {
      const double sigma = c.at(t + h);
      double decay[2], gain[2];
      for (int l = 0; l < 2; ++l) {
        decay[l] = std::exp(-h / tr.spectrum_tau_s[l]);
        gain[l] = tr.spectrum_tau_s[l] * (1 - decay[l]) / h;
      }
      double x = e;
      for (int it = 0; it < 50; ++it) {
        double r = tr.viscosity_pa_s * (x - e) / h + f.value(x) - sigma, dr = tr.viscosity_pa_s / h + f.slope(x);
        for (int l = 0; l < 2; ++l) {
          r += tr.spectrum_pa[l] * (decay[l] * hl[l] + (x - e) * gain[l]);
          dr += tr.spectrum_pa[l] * gain[l];
        }
        const double dx = r / dr;
        x -= dx;
        if (std::abs(dx) < 1e-15) break;
      }
      for (int l = 0; l < 2; ++l) hl[l] = decay[l] * hl[l] + (x - e) * gain[l];
      e = x;
      t += h;
      f.advance(e, h);
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace

LabDatasetTruth write_lab_dataset(unsigned seed, LabTruth truth, double size, const std::string& folder) {
  std::mt19937_64 rng(0x5eed0000ull + seed * 131ull + static_cast<unsigned>(truth) * 1000003ull + static_cast<unsigned long long>(size * 1000));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto between = [&](double a, double b) { return a + (b - a) * u(rng); };
  const auto log_between = [&](double a, double b) { return std::exp(between(std::log(a), std::log(b))); };
  LabDatasetTruth tr;
  tr.truth = truth;
  tr.size = size;
  tr.modulus_pa = log_between(1e3, 100e3);
  tr.viscosity_pa_s = tr.modulus_pa * log_between(0.005, 0.05);
  // Simple shear in every other seed, but not for asymmetry: an isotropic solid's shear stress is
  // odd in the shear strain, so tension/compression asymmetry exists only under uniaxial load.
  tr.mode = seed % 2 || truth == LabTruth::asymmetry ? Mode::uniaxial : Mode::simple_shear;
  tr.noise_column = seed % 3 != 0;
  const double strain = between(0.05, 0.2);
  const bool stiffening = truth == LabTruth::exponential_stiffening || truth == LabTruth::broadband_and_stiffening;
  if (stiffening) tr.stiffening_b = between(1.5, 5.0) / strain * size;
  if (truth == LabTruth::polynomial_stiffening) tr.stiffening_b = between(1.5, 4.0) / strain * size;
  if (truth == LabTruth::asymmetry) tr.compression_ratio = 1 + ((u(rng) < 0.5 ? between(0.3, 0.6) : between(1.7, 3.0)) - 1) * size;
  if (truth == LabTruth::softening || truth == LabTruth::recovering_softening) tr.softening_d = between(0.3, 0.6) * size;
  if (truth == LabTruth::recovering_softening) tr.recovery_s = between(2.0, 10.0);
  if (truth == LabTruth::broadband || truth == LabTruth::broadband_and_stiffening)
    for (int l = 0; l < 2; ++l) {
      tr.spectrum_pa[l] = tr.modulus_pa * between(0.3, 1.0) * size;
      tr.spectrum_tau_s[l] = l == 0 ? log_between(0.3, 3.0) : log_between(5.0, 40.0);
    }
  if (truth == LabTruth::permanent_set) tr.yield_strain = strain * (1 - between(0.3, 0.6) * size);
  if (truth == LabTruth::rate_thinning) {
    tr.thinning_n = between(0.2, 0.5);
    tr.thinning_rate = strain;  // a strain per second
    tr.thinning_pa = tr.modulus_pa * strain * between(0.15, 0.4) * size;
  }
  if (truth == LabTruth::grip_slip) {
    tr.slip_stress_pa = tr.modulus_pa * strain * between(0.4, 0.7);
    tr.slip_fraction = between(0.1, 0.25) * size;
  }
  if (truth == LabTruth::power_law) {
    tr.power_pa = tr.modulus_pa * between(0.5, 1.5) * size;
    tr.power_alpha = between(0.1, 0.4);
    tr.power_tau0_s = log_between(0.01, 0.1);
  }

  Dataset d;
  d.name = std::string(name(truth)) + " truth at size " + std::to_string(size) + ", seed " + std::to_string(seed);
  d.mode = tr.mode;
  d.specimen = {between(0.005, 0.03), between(0.005, 0.02), between(0.001, 0.005), between(1000, 1100)};

  struct Spec {
    const char* file;
    Command c;
  };
  const std::vector<Spec> strain_tests = {
      {"ramp_0.05s.csv", ramp_hold(strain, 0.05, between(10, 30))},
      {"ramp_medium.csv", ramp_hold(strain, between(0.3, 1.0), between(10, 30))},
      {"ramp_slow.csv", ramp_hold(strain, between(3, 10), between(10, 30))},
      {"ramp_compression.csv", ramp_hold(-strain * between(0.5, 1.0), between(0.1, 1.0), between(10, 30))},
      {"cycles_growing.csv", growing_cycles(strain, between(1.0, 4.0))},
  };
  // The session: the tests in the order listed on one specimen, 60 s apart, unloaded between them:
  // the specimen's history (first loading's peaks, a permanent set, a slipped grip) carries from
  // one test to the next, a recovering softening recovers in the rests. A drifting load cell's
  // zero moves by 4-12% of the peak stress over the session.
  constexpr double kRest = 60.0;
  d.history = History::carried;
  Elastic specimen{tr};
  std::vector<std::vector<double>> times, stresses;
  double peak = 0;
  for (const auto& s : strain_tests) {
    times.push_back(sample_times(s.c, rng));
    stresses.push_back(stress_under_strain(tr, specimen, s.c, times.back()));
    specimen.advance(0.0, kRest);
    for (double v : stresses.back()) peak = std::max(peak, std::abs(v));
  }
  std::vector<double> session_start;
  double session_s = 0;
  for (const auto& s : strain_tests) {
    session_start.push_back(session_s);
    session_s += s.c.end() + kRest;
  }
  if (truth == LabTruth::instrument_drift) {
    tr.drift_pa_per_s = (u(rng) < 0.5 ? -1.0 : 1.0) * peak * between(0.04, 0.12) * size / session_s;
    for (std::size_t k = 0; k < strain_tests.size(); ++k)
      for (std::size_t i = 0; i < times[k].size(); ++i) stresses[k][i] += tr.drift_pa_per_s * (session_start[k] + times[k][i]);
  }
  tr.stress_noise_pa = peak * between(0.005, 0.02);
  std::normal_distribution<double> stress_noise(0.0, tr.stress_noise_pa);
  for (std::size_t k = 0; k < strain_tests.size(); ++k) {
    TestData t;
    t.file = strain_tests[k].file;
    t.control = Control::strain;
    t.time_s = times[k];
    for (std::size_t i = 0; i < t.time_s.size(); ++i) {
      t.strain.push_back(strain_tests[k].c.at(t.time_s[i]));
      t.stress_pa.push_back(stresses[k][i] + stress_noise(rng));
    }
    if (tr.noise_column) t.stress_sd_pa.assign(t.time_s.size(), tr.stress_noise_pa);
    d.tests.push_back(std::move(t));
  }

  if (truth != LabTruth::power_law && truth != LabTruth::rate_thinning) {
    // Creep and recovery: stress ramped in 0.05 s to what the virgin material carries at a
    // fraction of the strain, held, released in 0.05 s, recovery.
    const Elastic virgin{tr};
    const double level = virgin.value(strain * between(0.3, 0.8));
    Command c{{0.0}, {0.0}};
    c.to(0.05, level);
    c.to(between(5, 15), level);
    c.to(0.05, 0.0);
    c.to(between(5, 15), 0.0);
    TestData creep;
    creep.file = "creep_recovery.csv";
    creep.control = Control::stress;
    creep.time_s = sample_times(c, rng);
    // A drifting load cell reads the true stress plus its zero; the machine holds the reading at
    // the command, so the specimen carries the command less the drift (linear between knots).
    Command applied = c;
    for (std::size_t k = 0; k < applied.t.size(); ++k) applied.v[k] -= tr.drift_pa_per_s * (session_s + applied.t[k]);
    const std::vector<double> exact = strain_under_stress(tr, specimen, applied, creep.time_s, 1000);
    double largest = 0;
    for (double e : exact) largest = std::max(largest, std::abs(e));
    tr.strain_noise = largest * between(0.005, 0.02);
    tr.creep_stress_noise_pa = std::abs(level) * 0.005;
    std::normal_distribution<double> strain_noise(0.0, tr.strain_noise), load_noise(0.0, tr.creep_stress_noise_pa);
    for (std::size_t k = 0; k < exact.size(); ++k) {
      creep.strain.push_back(exact[k] + strain_noise(rng));
      creep.stress_pa.push_back(c.at(creep.time_s[k]) + load_noise(rng));
    }
    if (tr.noise_column) creep.stress_sd_pa.assign(creep.time_s.size(), tr.creep_stress_noise_pa);
    d.tests.push_back(std::move(creep));
  }
  write_dataset(d, folder);
  return tr;
}

LabDatasetTruth write_kelvin_voigt_lab_dataset(unsigned seed, const std::string& folder) {
  return write_lab_dataset(seed, LabTruth::none, 1.0, folder);
}

}  // namespace viscera::lab::test
