#include "viscera/lab/adequacy.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "viscera/lab/format_figures.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/stress_controlled.hpp"

namespace viscera::lab {

namespace {

enum Phase { loading, unloading, hold, reversal, phase_count };
constexpr const char* kPhaseNames[phase_count] = {"loading", "unloading", "hold", "reversal"};

/// Samples each side of a sample over which its command's direction is read.
constexpr std::size_t kWindow = 5;

/// Pearson's correlation of two equally long series (0 when either is constant).
double correlation(const std::vector<double>& x, const std::vector<double>& y) {
  const auto n = static_cast<double>(x.size());
  if (x.size() < 3) return 0.0;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

/// The phase of sample i of a command: held (changing by less than its own noise or 1% of its
/// range over the window), moving away from zero or towards it, or turning.
Phase phase_of(const std::vector<double>& c, std::size_t i, double still) {
  const std::size_t n = c.size();
  const std::size_t a = i >= kWindow ? i - kWindow : 0, b = std::min(n - 1, i + kWindow);
  const double before = c[i] - c[a], after = c[b] - c[i];
  if (std::abs(c[b] - c[a]) <= still && std::abs(before) <= still && std::abs(after) <= still) return hold;
  if (std::abs(before) > still && std::abs(after) > still && (before > 0) != (after > 0)) return reversal;
  const double direction = c[b] - c[a];
  return direction * c[i] > 0 ? loading : unloading;
}

/// What stands out in the residual, one sentence each.
std::vector<std::string> findings_of(const Adequacy& r) {
  std::vector<std::string> out;
  for (const auto& t : r.tests)
    if (t.judged && t.residual_to_noise > kAdequacyTestFactor)
      out.push_back(t.file + format_figures(": the residual is %.3gx its noise (its mean %.3gx)", t.residual_to_noise, t.mean_to_noise));
  const auto worst = std::max_element(r.phases.begin(), r.phases.end(), [](const auto& a, const auto& b) { return a.rms_to_noise < b.rms_to_noise; });
  if (worst != r.phases.end() && worst->samples > 0) {
    std::string s = "the residual is largest in the " + worst->phase + " phase" + format_figures(" (%.3gx the noise; ", worst->rms_to_noise);
    bool first = true;
    for (const auto& p : r.phases)
      if (&p != &*worst && p.samples > 0) {
        s += (first ? "" : ", ") + p.phase + format_figures(" %.3gx", p.rms_to_noise);
        first = false;
      }
    out.push_back(s + ")");
  }
  if (std::abs(r.correlation_amplitude) >= 0.3)
    out.push_back(format_figures(
        r.correlation_amplitude > 0 ? "it grows with the strain amplitude (correlation %.2f)" : "it is largest at small strains (correlation %.2f)",
        r.correlation_amplitude));
  if (std::abs(r.correlation_rate) >= 0.3)
    out.push_back(format_figures(r.correlation_rate > 0
                                     ? "it grows with the strain rate (correlation %.2f with log |rate|): a damping that is not linear in the rate?"
                                     : "it is largest at slow strain rates (correlation %.2f with log |rate|)",
                                 r.correlation_rate));
  if (std::abs(r.correlation_session_time) >= 0.5)
    out.push_back(format_figures("its sign follows the time since the session began (correlation %.2f): an instrument whose zero drifts?",
                                 r.correlation_session_time));
  if (r.set_samples >= 10 && std::abs(r.set_at_zero_to_noise) >= 2.0)
    out.push_back(
        format_figures("where the command comes back to zero after a large excursion the model is off by %.3gx the noise on average (%g samples): "
                       "a set that remains (permanent deformation, or a slip in the grips)?",
                       r.set_at_zero_to_noise, static_cast<double>(r.set_samples)));
  return out;
}

}  // namespace

Adequacy judge_adequacy(const MaterialModel& m, const Dataset& d) {
  Adequacy r;
  double residual_sq = 0, noise_sq = 0, session_s = 0, set_sum = 0;
  double phase_sq[phase_count] = {}, phase_n[phase_count] = {};
  std::vector<double> z_sq, amplitude, z_moving_sq, log_rate, z_all, session_time;
  for (const TestData& t : d.tests) {
    const std::size_t n = t.time_s.size();
    if (n == 0) continue;
    const bool stress_control = t.control == Control::stress;
    const std::vector<double> predicted = predict_measured(m, t);
    const std::vector<double>& data = stress_control ? t.strain : t.stress_pa;
    const std::vector<double>& command = stress_control ? t.stress_pa : t.strain;
    const double scale = stress_control ? apparent_modulus_pa(t) : 1.0;
    const double noise = std::max(noise_level_pa(t), 1e-300);
    const auto [cmin, cmax] = std::minmax_element(command.begin(), command.end());
    const double command_peak = std::max(std::abs(*cmin), std::abs(*cmax));
    const double still = std::max(4 * noise_of_reading(command), 0.01 * (*cmax - *cmin));
    const auto [smin, smax] = std::minmax_element(t.strain.begin(), t.strain.end());
    const double strain_peak = std::max({std::abs(*smin), std::abs(*smax), 1e-300});
    TestAdequacy ta;
    ta.file = t.file;
    ta.judged = !stress_control;
    ta.session_start_s = session_s;
    double sq = 0, sum = 0;
    bool past_half = false;
    for (std::size_t i = 0; i < n; ++i) {
      const double z = (data[i] - predicted[i]) * scale / noise;
      sq += z * z;
      sum += z;
      const Phase p = phase_of(command, i, still);
      phase_sq[p] += z * z;
      phase_n[p] += 1;
      z_sq.push_back(z * z);
      amplitude.push_back(std::abs(t.strain[i]) / strain_peak);
      z_all.push_back(z);
      session_time.push_back(session_s + t.time_s[i] - t.time_s.front());
      if (p == loading || p == unloading) {
        const std::size_t a = i >= kWindow ? i - kWindow : 0, b = std::min(n - 1, i + kWindow);
        const double rate = (t.strain[b] - t.strain[a]) / std::max(t.time_s[b] - t.time_s[a], 1e-300);
        if (rate != 0) {
          z_moving_sq.push_back(z * z);
          log_rate.push_back(std::log10(std::abs(rate)));
        }
      }
      past_half = past_half || std::abs(command[i]) > 0.5 * command_peak;
      if (past_half && std::abs(command[i]) < 0.05 * command_peak) {
        set_sum += z;
        ++r.set_samples;
      }
    }
    ta.residual_to_noise = std::sqrt(sq / static_cast<double>(n));
    ta.mean_to_noise = sum / static_cast<double>(n);
    residual_sq += ta.residual_to_noise * ta.residual_to_noise * noise * noise;
    noise_sq += noise * noise;
    session_s += t.time_s.back() - t.time_s.front();
    r.tests.push_back(ta);
  }
  r.residual_to_noise = noise_sq > 0 ? std::sqrt(residual_sq / noise_sq) : 0.0;
  for (int p = 0; p < phase_count; ++p)
    r.phases.push_back({kPhaseNames[p], phase_n[p] > 0 ? std::sqrt(phase_sq[p] / phase_n[p]) : 0.0, static_cast<std::size_t>(phase_n[p])});
  r.correlation_amplitude = correlation(z_sq, amplitude);
  r.correlation_rate = correlation(z_moving_sq, log_rate);
  r.correlation_session_time = correlation(z_all, session_time);
  r.set_at_zero_to_noise = r.set_samples > 0 ? set_sum / static_cast<double>(r.set_samples) : 0.0;
  r.explained = r.residual_to_noise <= kAdequacyFactor;
  for (const auto& t : r.tests) r.explained = r.explained && (!t.judged || t.residual_to_noise <= kAdequacyTestFactor);
  r.findings = findings_of(r);
  return r;
}

}  // namespace viscera::lab
