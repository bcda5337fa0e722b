#include "viscera/lab/analysis.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <optional>
#include <sstream>

#include "viscera/common/input_error.hpp"
#include "viscera/lab/decimation.hpp"
#include "viscera/lab/fit.hpp"
#include "viscera/lab/format_figures.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/softening_evidence.hpp"
#include "viscera/lab/specimen_check.hpp"
#include "viscera/lab/stress_controlled.hpp"
#include "viscera/lab/test_history.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

namespace viscera::lab {

namespace {

// Acceptance: a mechanism must lower the held-out mean square error by more than kNoiseFraction
// of the noise variance, and the held-out RMS by at least kMinGain relatively.
constexpr double kNoiseFraction = 0.5;
constexpr double kMinGain = 0.05;
// First-load softening needs the data's own evidence (softening_evidence) at this z-score.
constexpr double kSofteningZ = 3.0;
// Held-out blocks per test (evaluate()).
constexpr std::size_t kBlocks = 4;

// Residual signatures of a fitted model (data - model), the evidence behind each mechanism.
std::string evidence(Mechanism m, const MaterialModel& model, const Dataset& d) {
  double hold_drift = 0, hold_n = 0, big = 0, big_n = 0, mid = 0, mid_n = 0, small = 0, small_n = 0, comp = 0, comp_n = 0, tens = 0, tens_n = 0;
  double virgin = 0, virgin_n = 0, reload = 0, reload_n = 0;
  double max_strain = 0;
  for (const auto& t : d.tests)
    for (double e : t.strain) max_strain = std::max(max_strain, std::abs(e));
  for (const auto& t : d.tests) {
    const auto y = predict_stress(model, t);
    double peak_t = t.before_tension, peak_c = t.before_compression;
    for (std::size_t k = 0; k < y.size(); ++k) {
      const double r = t.stress_pa[k] - y[k], e = t.strain[k];
      if (k > 1 && std::abs(e - t.strain[k - 1]) < 1e-4 * max_strain && std::abs(t.strain[k - 1] - t.strain[k - 2]) < 1e-4 * max_strain) {
        hold_drift += r - (t.stress_pa[k - 1] - y[k - 1]);
        ++hold_n;
      }
      if (std::abs(e) > 0.7 * max_strain)
        big += r, ++big_n;
      else if (std::abs(e) > 0.2 * max_strain)
        mid += r, ++mid_n;
      else if (std::abs(e) > 0.01 * max_strain)
        small += r * (e < 0 ? -1 : 1), ++small_n;
      if (e < -0.05 * max_strain) comp += r * (e < 0 ? -1 : 1), ++comp_n;
      if (e > 0.05 * max_strain) tens += r, ++tens_n;
      const double peak = e >= 0 ? peak_t : peak_c;
      if (std::abs(e) > 0.3 * max_strain) {
        if (std::abs(e) >= peak)
          virgin += r * (e >= 0 ? 1 : -1), ++virgin_n;
        else
          reload += r * (e >= 0 ? 1 : -1), ++reload_n;
      }
      if (e >= 0)
        peak_t = std::max(peak_t, e);
      else
        peak_c = std::max(peak_c, -e);
    }
  }
  const auto mean = [](double s, double n) { return n > 0 ? s / n : 0.0; };
  switch (m) {
    case Mechanism::broadband_relaxation:
      return format_figures("during holds the measured stress keeps changing against the model: mean drift %.3g Pa per sample over %.0f hold samples",
                            mean(hold_drift, hold_n), hold_n);
    case Mechanism::strain_stiffening:
      return format_figures("secant stiffness grows with strain: mean residual %.3g Pa above 70%% of the largest strain, %.3g Pa at 20-70%%",
                            mean(big, big_n), mean(mid, mid_n));
    case Mechanism::tension_compression_asymmetry:
      return format_figures("tension and compression differ: mean residual %.3g Pa in tension, %.3g Pa (sign-corrected) in compression",
                            mean(tens, tens_n), mean(comp, comp_n));
    case Mechanism::first_load_softening:
      return format_figures("first loading stiffer than reloading: mean residual %.3g Pa on virgin loading, %.3g Pa on reloading",
                            mean(virgin, virgin_n), mean(reload, reload_n));
    case Mechanism::contact_take_up:
      return format_figures(
          "the first loading carries less than the model: mean residual %.3g Pa (sign-corrected; positive: less stress than the model) "
          "below 20%% of the largest strain, %.3g Pa at 20-70%%",
          -mean(small, small_n), mean(mid, mid_n));
  }
  return "";
}

double rms_over_tests(const std::vector<TestFigures>& t, double TestFigures::*f) {
  double s = 0;
  for (const auto& x : t) s += (x.*f) * (x.*f);
  return std::sqrt(s / static_cast<double>(t.size()));
}

}  // namespace

ModelEvaluation evaluate(const MaterialModel& structure, const Dataset& d, HeldOut unit) {
  if (d.tests.size() < 2) throw common::InputError(d.folder, 0, "tests", "at least two tests are needed to measure errors on held-out tests");
  ModelEvaluation ev;
  std::vector<const TestData*> all;
  for (const auto& t : d.tests) all.push_back(&t);
  // Held-out units (HeldOut): whole tests, or each test in kBlocks consecutive blocks of rows. For
  // a block the model is fitted to every row of every test but the block's, runs through the whole
  // history (driven by the measured strain or stress) and predicts the block. Either way every row
  // is predicted once by a fit that did not see it. The fits are independent: both cores.
  struct Fold {
    std::size_t test, begin, end;
  };
  std::vector<Fold> folds;
  for (std::size_t k = 0; k < d.tests.size(); ++k) {
    const std::size_t n = d.tests[k].time_s.size(), blocks = unit == HeldOut::blocks && n >= 4 * kBlocks ? kBlocks : 1;
    for (std::size_t b = 0; b < blocks; ++b) folds.push_back({k, n * b / blocks, n * (b + 1) / blocks});
  }
  std::vector<std::vector<double>> predicted(d.tests.size());
  for (std::size_t k = 0; k < d.tests.size(); ++k) predicted[k].resize(d.tests[k].time_s.size());
  const auto run = [&](std::size_t from, std::size_t step) {
    for (std::size_t f = from; f < folds.size(); f += step) {
      const TestData& t = d.tests[folds[f].test];
      MaterialModel fitted;
      if (folds[f].begin == 0 && folds[f].end == t.time_s.size()) {  // the whole test: fit the others
        std::vector<const TestData*> others;
        for (const TestData* o : all)
          if (o != &t) others.push_back(o);
        fitted = fit_model(structure, others);
      } else {
        fitted = fit_model(structure, all, {&t, folds[f].begin, folds[f].end});
      }
      const std::vector<double> y = predict_measured(fitted, t);
      for (std::size_t j = folds[f].begin; j < folds[f].end; ++j) predicted[folds[f].test][j] = y[j];
    }
  };
  auto half = std::async(std::launch::async, [&] {
    run(0, 2);
    return fit_model(structure, all);  // and the fit to everything
  });
  run(1, 2);
  ev.model = half.get();
  std::vector<double> heldout(d.tests.size());
  for (std::size_t k = 0; k < d.tests.size(); ++k) {
    const TestData& t = d.tests[k];
    const std::vector<double>& measured = t.control == Control::strain ? t.stress_pa : t.strain;
    double sq = 0.0;
    for (std::size_t j = 0; j < measured.size(); ++j) sq += (predicted[k][j] - measured[j]) * (predicted[k][j] - measured[j]);
    heldout[k] = std::sqrt(sq / static_cast<double>(measured.size())) * (t.control == Control::strain ? 1.0 : apparent_modulus_pa(t));
  }
  for (std::size_t k = 0; k < d.tests.size(); ++k) {
    const TestData& t = d.tests[k];
    TestFigures f{t.file, rms_error_pa(ev.model, t), heldout[k], noise_level_pa(t)};
    if (t.control == Control::stress) {
      const double modulus = apparent_modulus_pa(t);
      f.fit_rms_strain = f.fit_rms_pa / modulus;
      f.heldout_rms_strain = f.heldout_rms_pa / modulus;
      f.noise_strain = f.noise_pa / modulus;
    }
    ev.tests.push_back(f);
  }
  ev.fit_rms_pa = rms_over_tests(ev.tests, &TestFigures::fit_rms_pa);
  ev.heldout_rms_pa = rms_over_tests(ev.tests, &TestFigures::heldout_rms_pa);
  return ev;
}

namespace {

struct Selection {
  ModelEvaluation final;
  std::vector<Mechanism> causes;
  std::vector<Candidate> candidates;
};

double noise_of(const Dataset& d) {
  double n2 = 0;
  for (const auto& t : d.tests) n2 += noise_level_pa(t) * noise_level_pa(t);
  return std::sqrt(n2 / static_cast<double>(d.tests.size()));
}

// Rounds of candidates on top of `start`: the best mechanism whose held-out gain is above the
// noise joins the model, the others are tried again on top of it.
Selection select_mechanisms(const ModelEvaluation& start, const Dataset& d, double noise_pa, const std::function<void(const std::string&)>& say) {
  // How long the rest will take: at most 4 + 3 + 2 + 1 candidate evaluations, each timed.
  const auto started = std::chrono::steady_clock::now();
  int evaluated = 0;
  Selection sel;
  ModelEvaluation current = start;
  std::vector<Mechanism> remaining(kMechanisms.begin(), kMechanisms.end());
  // In simple shear an isotropic solid's stress is odd in the strain: no tension/compression
  // asymmetry to find there (and stiffening is offered in its odd forms only).
  if (start.model.odd_only) remaining.erase(std::find(remaining.begin(), remaining.end(), Mechanism::tension_compression_asymmetry));
  // A contact to take up only where the specimen sat between platens.
  if (!start.model.platens) remaining.erase(std::find(remaining.begin(), remaining.end(), Mechanism::contact_take_up));
  const int at_most = static_cast<int>(remaining.size() * (remaining.size() + 1) / 2);
  for (int round = 1; !remaining.empty(); ++round) {
    std::optional<ModelEvaluation> current_blocks;  // the current model on held-out blocks, when needed
    const Mechanism* best = nullptr;
    ModelEvaluation best_eval;
    double best_gain = 0.0;
    for (const Mechanism& m : remaining) {
      MaterialModel s = current.model;
      s.mechanisms |= 1u << static_cast<unsigned>(m);
      const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      say(std::string("round ") + std::to_string(round) + ": trying " + name(m) + " (candidate " + std::to_string(evaluated + 1) + " of at most " +
          std::to_string(at_most) +
          (evaluated > 0 ? format_figures("; at most about %.0f s left", spent / evaluated * (at_most - evaluated)) : std::string()) + ")");
      const ModelEvaluation ev = evaluate(s, d);
      ++evaluated;
      Candidate c{m, round, current.heldout_rms_pa, ev.heldout_rms_pa, false, evidence(m, current.model, d)};
      const double reduction = current.heldout_rms_pa * current.heldout_rms_pa - ev.heldout_rms_pa * ev.heldout_rms_pa;
      bool above_noise = gain_holds(current.heldout_rms_pa, ev.heldout_rms_pa, noise_pa);
      say(format_figures("  held-out RMS %.4g -> %.4g Pa (noise %.4g Pa)", current.heldout_rms_pa, ev.heldout_rms_pa, noise_pa) +
          (above_noise ? ": gain above noise" : ": no gain above noise"));
      double gain_measure = reduction;
      if (m == Mechanism::first_load_softening) {
        // Softening only where the data show it: on reloading below the previous peak, at the
        // same strain, the stress differs from first loading's.
        // Where the tests carry their specimen's history, it may also have recovered between
        // them: both looks, the stronger kept.
        SofteningEvidence se = softening_evidence(current.model, d, noise_pa, false);
        if (current.model.history_carried)
          if (const SofteningEvidence across = softening_evidence(current.model, d, noise_pa, true); across.z > se.z) se = across;
        char text[320];
        std::snprintf(text, sizeof text,
                      "; at the same strain, first loading against reloading below the previous peak (%s): z = %.2f over %d strain bins (%ld "
                      "and %ld samples)%s",
                      se.across_tests ? "across the session's tests" : "within each test", se.z, se.bins, se.virgin, se.below_peak,
                      se.z > kSofteningZ ? "" : ": not the evidence softening needs (z > 3)");
        c.evidence += text;
        if (above_noise && se.z <= kSofteningZ) {
          above_noise = false;
          say(format_figures("  rejected: no first loading stiffer than reloading at the same strain (z = %.2f)", se.z));
        }
        if (!above_noise && se.z > kSofteningZ) {
          // Reloading is often in one test only (the cyclic one), so no other test can show the
          // gain: judged on held-out blocks of the tests instead (HeldOut::blocks).
          if (!current_blocks) current_blocks = evaluate(current.model, d, HeldOut::blocks);
          const ModelEvaluation eb = evaluate(s, d, HeldOut::blocks);
          const double rb = current_blocks->heldout_rms_pa * current_blocks->heldout_rms_pa - eb.heldout_rms_pa * eb.heldout_rms_pa;
          above_noise = gain_holds(current_blocks->heldout_rms_pa, eb.heldout_rms_pa, noise_pa);
          gain_measure = rb;
          c.evidence += format_figures("; on held-out blocks of the tests (reloading shows within a test): held-out RMS %.4g -> %.4g Pa",
                                       current_blocks->heldout_rms_pa, eb.heldout_rms_pa);
          say(format_figures("  on held-out blocks: %.4g -> %.4g Pa", current_blocks->heldout_rms_pa, eb.heldout_rms_pa) +
              (above_noise ? ": gain above noise" : ": no gain above noise"));
        }
      }
      if (above_noise && gain_measure > best_gain) {
        best_gain = gain_measure;
        best = &m;
        best_eval = ev;
      }
      sel.candidates.push_back(c);
    }
    if (!best) break;
    for (auto& c : sel.candidates)
      if (c.round == round && c.mechanism == *best) c.accepted = true;
    sel.causes.push_back(*best);
    say(std::string("accepted ") + name(*best));
    current = best_eval;
    remaining.erase(std::find(remaining.begin(), remaining.end(), *best));
  }
  sel.final = current;
  return sel;
}

}  // namespace

const char* to_string(CausesStatus s) {
  switch (s) {
    case CausesStatus::none: return "none";
    case CausesStatus::confirmed: return "confirmed";
    case CausesStatus::not_confirmed: return "not_confirmed";
    case CausesStatus::tentative: return "tentative";
  }
  return "?";
}

bool gain_holds(double before_pa, double after_pa, double noise_pa) {
  return before_pa * before_pa - after_pa * after_pa > kNoiseFraction * noise_pa * noise_pa && after_pa < (1.0 - kMinGain) * before_pa;
}

namespace {

/// The honest gain: for each test, the whole selection runs on the other tests only (its own
/// leave-one-out inside), the chosen model is fitted to them and predicts the test.
void measure_nested(Analysis& a, const Dataset& d, const MaterialModel& structure, const std::function<void(const std::string&)>& say) {
  double sq = 0.0;
  for (std::size_t k = 0; k < d.tests.size(); ++k) {
    say("nested leave-one-out: choosing the mechanisms without " + d.tests[k].file + " (" + std::to_string(k + 1) + " of " +
        std::to_string(d.tests.size()) + ")");
    Dataset others = d;
    others.tests.erase(others.tests.begin() + static_cast<long>(k));
    const Selection fold = select_mechanisms(evaluate(structure, others), others, noise_of(others), [](const std::string&) {});
    std::vector<const TestData*> fit_on;
    for (const auto& t : others.tests) fit_on.push_back(&t);
    const double e = rms_error_pa(fit_model(fold.final.model, fit_on), d.tests[k]);
    a.nested.push_back({d.tests[k].file, fold.causes, e});
    sq += e * e;
  }
  a.nested_heldout_rms_pa = std::sqrt(sq / static_cast<double>(d.tests.size()));
  a.nested_gain = a.baseline.heldout_rms_pa / a.nested_heldout_rms_pa;
  say(format_figures("nested leave-one-out: held-out RMS %.4g Pa (gain %.3gx) where the selection never saw the test; ", a.nested_heldout_rms_pa,
                     a.nested_gain) +
      format_figures("%.4g Pa (gain %.3gx) for the model chosen on all tests", a.final.heldout_rms_pa, a.gain));
}

/// The verdict in words: what the baseline misses, whether the choice holds on data it did not see,
/// what remains above the noise, and whether the two noise estimates agree.
std::string verdict_of(const Analysis& a, bool odd_only) {
  std::ostringstream v;
  const auto list = [&](const std::vector<Mechanism>& ms) {
    for (std::size_t k = 0; k < ms.size(); ++k) v << (k ? ", " : "") << name(ms[k]);
  };
  int same = 0;
  for (const auto& f : a.nested) same += f.causes == a.causes;
  const auto nested_figures = [&] {
    v << "chosen without each test in turn (nested leave-one-out), the model predicts the tests that played no part in choosing it "
         "with an RMS error of "
      << a.nested_heldout_rms_pa << " Pa (gain " << a.nested_gain << "x over the baseline); " << same << " of " << a.nested.size()
      << " folds chose the same mechanisms.";
  };
  switch (a.causes_status) {
    case CausesStatus::none:
      v << "The baseline (linear elasticity with Kelvin-Voigt damping) explains the data: no candidate mechanism lowers "
           "the held-out error by more than the noise allows.";
      break;
    case CausesStatus::confirmed:
    case CausesStatus::tentative:
      v << (a.causes_status == CausesStatus::confirmed ? "The baseline misses: " : "Tentatively, the baseline misses: ");
      list(a.causes);
      v << ". Adding them lowers the held-out RMS error from " << a.baseline.heldout_rms_pa << " Pa to " << a.final.heldout_rms_pa << " Pa (gain "
        << a.gain << "x; noise " << a.noise_pa << " Pa).";
      if (a.causes_status == CausesStatus::confirmed) {
        v << " The choice holds on data it did not see: ";
        nested_figures();
      } else {
        v << " Tentative because every test had a say in the choice and no honest gain was measured: " << a.nested_not_run << ".";
      }
      break;
    case CausesStatus::not_confirmed:
      v << "No cause is named as found. Chosen on all tests, ";
      list(a.causes);
      v << " lowered the held-out RMS error from " << a.baseline.heldout_rms_pa << " Pa to " << a.final.heldout_rms_pa << " Pa (gain " << a.gain
        << "x), but the choice does not hold where it never saw the test: ";
      nested_figures();
      v << " The baseline is the model this analysis stands by (model.json).";
      break;
  }
  if (odd_only)
    v << " Simple shear: tension/compression asymmetry was not a candidate and stiffening was offered in its odd forms only (an "
         "isotropic solid's shear stress is odd in the shear strain).";
  if (a.supported_model().has(Mechanism::strain_stiffening))
    v << " Stiffening form chosen by the fit: " << name(a.supported_model().stiffening_form) << ".";
  if (const MaterialModel& m = a.supported_model(); m.has(Mechanism::first_load_softening) && m.history_carried)
    v << " The tests were one session on their specimen: each starts with " << 100 * m.softening_kept
      << "% of the largest strain the tests before it reached as the softening's memory (100%: nothing recovered between tests).";
  if (a.supported_model().platens) {
    v << " Between platens: the model's stress is never a pull (contact is lost where it would pull)";
    if (a.supported_model().has(Mechanism::contact_take_up))
      v << ", and the platens closed a gap of " << 100 * a.supported_model().contact_strain
        << "% of the specimen's height before they loaded it (contact_take_up: a property of the test, left out of the material handed to the "
           "organ)";
    v << ".";
  }
  if (const Adequacy& q = a.adequacy; q.explained) {
    v << " The model it stands by explains the data within the noise: its residual is " << q.residual_to_noise << "x the noise.";
  } else {
    v << " The model it stands by does not explain the data: its residual is " << q.residual_to_noise << "x the noise (at most " << kAdequacyFactor
      << "x over the tests and " << kAdequacyTestFactor
      << "x on any strain-controlled test would be explained). Something outside the lab's catalogue remains";
    for (std::size_t k = 0; k < q.findings.size(); ++k) v << (k ? "; " : ": ") << q.findings[k];
    v << "." << (a.named_causes().empty() ? "" : " The causes named are the catalogue's best help, not the whole explanation.");
  }
  if (const NoiseCheck& c = a.noise_check; !c.agree)
    v << " The two noise estimates disagree: " << c.first_pa
      << (c.first_stated ? " Pa from the data's stress_sd_pa, " : " Pa from the differences between neighbouring samples, ") << c.holds_pa
      << " Pa from the spread in the holds (" << c.holds << " holds, about a running mean over " << c.window_s << " s); "
      << (c.holds_pa > c.first_pa ? "the noise is correlated over many samples (a logger's filter, or drift), so every ratio to the noise above "
                                    "is too large by up to that factor."
                                  : "the first is too large (a stated SD that is the spread between specimens rather than the instrument's "
                                    "noise, or steps between samples), so every ratio to the noise above is too small by up to that factor.");
  return v.str();
}

}  // namespace

Analysis analyze(const Dataset& measured, const std::function<void(const std::string&)>& progress, const AnalyzeOptions& options) {
  const auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  Dataset with_history = measured;  // each test's start, from the commands of the tests before it
  carry_history(with_history);
  const Dataset d = decimate(with_history, options.max_fit_points);
  Analysis a;
  for (std::size_t k = 0; k < d.tests.size(); ++k)
    if (d.tests[k].time_s.size() < measured.tests[k].time_s.size()) {
      a.decimated.push_back(d.tests[k].file + ": " + std::to_string(measured.tests[k].time_s.size()) + " rows, fitted on " +
                            std::to_string(d.tests[k].time_s.size()) + " of them (kept evenly along time and strain; noise measured on every row)");
      say(a.decimated.back());
    }
  a.dataset = d.name;
  a.noise_pa = noise_of(d);
  a.noise_check = check_noise(measured);  // every row: the holds' running means need the original sampling
  if (a.noise_check.tests > 0)
    say(format_figures("noise: %.4g Pa from second differences; %.4g Pa from the spread in ", a.noise_check.first_pa, a.noise_check.holds_pa) +
        std::to_string(a.noise_check.holds) + " holds" + (a.noise_check.agree ? " (they agree)" : " (they disagree)"));
  MaterialModel structure = for_dataset({}, d);
  structure.relaxation_time_s = relaxation_times_for(d);
  say("fitting the baseline (linear elastic + Kelvin-Voigt) to " + std::to_string(d.tests.size()) + " tests, leaving each out in turn");
  a.baseline = evaluate(structure, d);
  say(format_figures("baseline: fit RMS %.4g Pa, held-out RMS %.4g Pa, noise %.4g Pa", a.baseline.fit_rms_pa, a.baseline.heldout_rms_pa, a.noise_pa));
  Selection sel = select_mechanisms(a.baseline, d, a.noise_pa, say);
  a.causes = sel.causes;
  a.candidates = sel.candidates;
  const ModelEvaluation current = sel.final;
  a.final = current;
  a.gain = a.baseline.heldout_rms_pa / a.final.heldout_rms_pa;
  if (!options.nested)
    a.nested_not_run = "the nested leave-one-out was turned off";
  else if (d.tests.size() < 3)
    a.nested_not_run = std::to_string(d.tests.size()) + (d.tests.size() == 1 ? " test" : " tests") +
                       ": the nested leave-one-out needs at least 3 (a selection on the other tests, held out within them)";
  if (a.nested_not_run.empty()) measure_nested(a, d, structure, say);
  if (!a.causes.empty())
    a.causes_status = !a.nested_not_run.empty()                                                    ? CausesStatus::tentative
                      : gain_holds(a.baseline.heldout_rms_pa, a.nested_heldout_rms_pa, a.noise_pa) ? CausesStatus::confirmed
                                                                                                   : CausesStatus::not_confirmed;
  a.adequacy = judge_adequacy(a.supported_model(), d);
  say(a.adequacy.explained ? format_figures("adequacy: explained (residual %.3gx the noise)", a.adequacy.residual_to_noise)
                           : format_figures("adequacy: not explained (residual %.3gx the noise)", a.adequacy.residual_to_noise));
  if (options.bootstrap_replicates > 0 && d.tests.size() >= 3)
    say("parameter uncertainties: a bootstrap over tests, " + std::to_string(options.bootstrap_replicates) + " draws");
  a.uncertainty = bootstrap_over_tests(a.supported_model(), d, options.bootstrap_replicates);
  if (options.specimen) {
    say("simulating baseline and final model on the tetrahedral specimen (GPS, implicit, inertia)");
    a.specimen.push_back(check_on_specimen(a.baseline.model, d, say));
    if (!a.causes.empty()) a.specimen.push_back(check_on_specimen(a.final.model, d, say));
    for (const auto& c : a.specimen) say("  " + c.model + (c.ran ? ": done" : ": " + c.note));
  }
  a.verdict = verdict_of(a, structure.odd_only);
  return a;
}

}  // namespace viscera::lab
