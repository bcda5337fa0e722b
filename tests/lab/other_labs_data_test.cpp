// The lab on data shaped like other laboratories' (issue 38): the verdict stands on the honest  // SPDX-License-Identifier: Apache-2.0
// gain, the noise is checked by a second path and survives quantised forces, and a specimen run
// that cannot finish stops and says where. The data here come from a generator of their own (not the lab's synthetic one): a standard linear solid (a
// spring beside one Maxwell arm, relaxation time 20 s) stretched in four ramp-and-hold tests to
// 10-40% strain, like the blood clots of issue 38. Only the noise is random. Truths and forms the lab's catalogue was not
// built on: one relaxation time (not a broad band), specimens that differ from test to test, and
// noise that a logger's filter has correlated over many samples.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/lab/analysis.hpp"
#include "viscera/lab/fit.hpp"
#include "viscera/lab/lab_import.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/specimen_simulation.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

using namespace viscera::lab;

namespace {

struct Truth {
  std::vector<double> specimen_scale{1, 1, 1, 1};  ///< each test's moduli times this (different specimens)
  double noise_sd_pa = 5.0;
  double noise_correlation = 0.0;  ///< AR(1) coefficient from sample to sample (0: white)
  double rate_hz = 10.0;
  double hold_rate_hz = 0.0;  ///< sampling in the holds (0: rate_hz, one rate throughout)
  double hold_s = 300.0;
  std::size_t tests = 4;
  unsigned seed = 1;
};

/// Ramps at 0.02 1/s to 0.1, 0.2, ... strain, each held hold_s; E = 2 kPa beside a 1.5 kPa Maxwell arm.
Dataset clot_like(const Truth& truth) {
  std::mt19937 rng(truth.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Dataset d;
  d.name = "clot-like";
  d.folder = "generated";
  d.mode = Mode::uniaxial;
  d.specimen = {0.01, 0.003, 0.003, 1050};
  const double tau = 20.0, dt = 1.0 / truth.rate_hz, rate = 0.02;
  const double rho = truth.noise_correlation, innovation = std::sqrt(1 - rho * rho);
  for (std::size_t k = 0; k < truth.tests; ++k) {
    const double amp = 0.1 * static_cast<double>(k + 1), scale = truth.specimen_scale[k];
    const double e = 2000 * scale, e1 = 1500 * scale;
    TestData t;
    t.file = "s" + std::to_string(k + 1) + ".csv";
    std::vector<double> times;
    if (truth.hold_rate_hz <= 0) {
      const auto n = static_cast<std::size_t>((amp / rate + truth.hold_s) / dt);
      for (std::size_t i = 0; i <= n; ++i) times.push_back(static_cast<double>(i) * dt);
    } else {  // the ramp sampled at rate_hz, the hold at hold_rate_hz from the ramp's end
      for (std::size_t i = 0; static_cast<double>(i) * dt < amp / rate; ++i) times.push_back(static_cast<double>(i) * dt);
      for (double s = amp / rate; s <= amp / rate + truth.hold_s; s += 1.0 / truth.hold_rate_hz) times.push_back(s);
    }
    double q = 0, previous = 0, noise = 0;
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double time = times[i], eps = std::min(amp, rate * time), h = i > 0 ? time - times[i - 1] : dt;
      // The Maxwell arm's stress, exact for a strain linear over each sample interval.
      if (i > 0) q = q * std::exp(-h / tau) + e1 * (eps - previous) * (tau / h) * (1 - std::exp(-h / tau));
      noise = rho * noise + innovation * truth.noise_sd_pa * gauss(rng);
      t.time_s.push_back(time);
      t.strain.push_back(eps);
      t.stress_pa.push_back(e * eps + q + noise);
      previous = eps;
    }
    d.tests.push_back(std::move(t));
  }
  return d;
}

const AnalyzeOptions kWithoutSpecimen{.specimen = false};

}  // namespace

// One specimen, relaxation present: the choice holds on the tests it never saw.
TEST(HonestGain, OneSpecimenRelaxationIsConfirmed) {
  const Analysis a = analyze(clot_like({}), {}, kWithoutSpecimen);
  ASSERT_FALSE(a.causes.empty());
  EXPECT_EQ(a.causes[0], Mechanism::broadband_relaxation);
  EXPECT_EQ(a.causes_status, CausesStatus::confirmed) << a.verdict;
  EXPECT_TRUE(gain_holds(a.baseline.heldout_rms_pa, a.nested_heldout_rms_pa, a.noise_pa));
  EXPECT_EQ(a.named_causes(), a.causes);
  std::printf("[ figure ] one specimen: gain %.2fx, honest gain %.2fx: %s\n", a.gain, a.nested_gain, to_string(a.causes_status));
}

// Four specimens whose moduli differ by up to 30%. The relaxation is in the truth, but the
// differences between specimens are larger than what it explains: chosen on all tests it lowers
// the held-out error a little (each test had a say in the choice), yet a selection that never
// saw a specimen predicts it no better than the baseline. The honest call on four specimens this
// different is to name nothing as found, say why, and stand by the baseline, as on the clots of
// issue 38 (1.83x on all tests, 0.92x honest). Two orders of the same four specimens.
TEST(HonestGain, SpecimensThatDifferHideTheGainAndNothingIsNamed) {
  for (const std::vector<double>& scales : {std::vector<double>{1.3, 1.0, 0.8, 1.15}, std::vector<double>{1.0, 1.3, 0.8, 1.15}}) {
    Truth truth;
    truth.specimen_scale = scales;
    const Analysis a = analyze(clot_like(truth), {}, kWithoutSpecimen);
    ASSERT_FALSE(a.causes.empty()) << "the selection on all tests chose nothing, so this case tests nothing";
    EXPECT_EQ(a.causes_status, CausesStatus::not_confirmed) << a.verdict;
    EXPECT_FALSE(gain_holds(a.baseline.heldout_rms_pa, a.nested_heldout_rms_pa, a.noise_pa));
    EXPECT_TRUE(a.named_causes().empty());
    EXPECT_EQ(a.supported_model().describe(), a.baseline.model.describe());
    EXPECT_NE(a.verdict.find("No cause is named as found"), std::string::npos) << a.verdict;
    std::printf("[ figure ] specimens x%.2f %.2f %.2f %.2f: gain %.2fx on all tests, honest gain %.2fx: %s\n", scales[0], scales[1], scales[2],
                scales[3], a.gain, a.nested_gain, to_string(a.causes_status));
  }
}

// Two tests: the nesting cannot run; the causes are tentative and the analysis says why.
TEST(HonestGain, TwoTestsNameCausesAsTentativeAndSayWhy) {
  Truth truth;
  truth.tests = 2;
  const Analysis a = analyze(clot_like(truth), {}, kWithoutSpecimen);
  EXPECT_TRUE(a.nested.empty());
  EXPECT_NE(a.nested_not_run.find("2 tests"), std::string::npos) << a.nested_not_run;
  ASSERT_FALSE(a.causes.empty());
  EXPECT_EQ(a.causes_status, CausesStatus::tentative);
  EXPECT_NE(a.verdict.find("Tentatively"), std::string::npos) << a.verdict;
  EXPECT_NE(a.verdict.find(a.nested_not_run), std::string::npos) << a.verdict;
}

// The second noise estimate against the truth: white noise, both agree with the SD generated;
// noise correlated from sample to sample (AR(1), 0.9: about ten samples), the second differences
// see about a quarter of it, the holds nearly all, and the analysis says they disagree.
TEST(Noise, TheHoldsFindTheGeneratedSDWhereSecondDifferencesCannot) {
  for (const double rho : {0.0, 0.9}) {
    Truth truth;
    truth.noise_sd_pa = 10.0;
    truth.noise_correlation = rho;
    truth.rate_hz = 100.0;
    truth.hold_s = 30.0;
    const Dataset d = clot_like(truth);
    for (const auto& t : d.tests) {
      const HoldNoise h = noise_in_holds(t);
      ASSERT_EQ(h.holds, 1) << t.file;
      EXPECT_NEAR(h.window_s, 1.01, 1e-9);
      // Correlated over about 10 of the window's 101 samples, the running mean takes about a
      // tenth of the variance with it: 0.9 of the SD is expected.
      EXPECT_NEAR(h.sd / truth.noise_sd_pa, rho == 0 ? 1.0 : 0.9, 0.1) << t.file << " rho " << rho;
      const double first = noise_level_pa(t);
      if (rho == 0)
        EXPECT_NEAR(first / truth.noise_sd_pa, 1.0, 0.1) << t.file;
      else
        EXPECT_LT(first / truth.noise_sd_pa, 0.4) << t.file;  // sqrt((6 - 8 rho + 2 rho^2) / 6) = 0.26
    }
    std::printf("[ figure ] noise SD 10 Pa, AR(1) %.1f: second differences %.2f Pa, spread in the holds %.2f Pa\n", rho, noise_level_pa(d.tests[0]),
                noise_in_holds(d.tests[0]).sd);
  }
}

TEST(HonestGain, CorrelatedNoiseIsReportedAsTwoEstimatesThatDisagree) {
  Truth truth;
  truth.noise_sd_pa = 10.0;
  truth.noise_correlation = 0.9;
  truth.rate_hz = 100.0;
  truth.hold_s = 30.0;
  const Analysis a = analyze(clot_like(truth), {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0});
  EXPECT_EQ(a.noise_check.tests, 4);
  EXPECT_FALSE(a.noise_check.agree);
  EXPECT_GT(a.noise_check.holds_pa, kNoiseAgreementFactor * a.noise_check.first_pa);
  EXPECT_NE(a.verdict.find("The two noise estimates disagree"), std::string::npos) << a.verdict;
  truth.noise_correlation = 0.0;
  EXPECT_TRUE(analyze(clot_like(truth), {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0}).noise_check.agree);
}

// A force logger's resolution coarser than its noise (the pig discs: 0.1 N, 1.3 kPa, over noise
// of about 0.3 kPa): more than half the second differences are exactly zero, and their median,
// the first estimate's, said the noise was 0 Pa (every ratio to it then 1e302); so did the median
// residual in the holds. Both now fall back on an RMS and the quantum: within half and twice the SD
// of what was recorded about the truth.
TEST(Noise, QuantisedForcesKeepTheirNoise) {
  Truth truth;
  truth.noise_sd_pa = 300.0;
  truth.rate_hz = 1.0;
  truth.hold_s = 1000.0;
  Dataset d = clot_like(truth);
  const double quantum = 1300.0;
  for (auto& t : d.tests) {
    double sq = 0;
    const Dataset exact = clot_like(Truth{.noise_sd_pa = 0.0, .rate_hz = 1.0, .hold_s = 1000.0});
    const auto& clean = exact.tests[static_cast<std::size_t>(&t - d.tests.data())].stress_pa;
    for (std::size_t k = 0; k < t.stress_pa.size(); ++k) {
      t.stress_pa[k] = quantum * std::round(t.stress_pa[k] / quantum);
      sq += (t.stress_pa[k] - clean[k]) * (t.stress_pa[k] - clean[k]);
    }
    const double recorded_sd = std::sqrt(sq / static_cast<double>(t.stress_pa.size()));
    const double first = noise_level_pa(t);
    EXPECT_GT(first, 0.5 * recorded_sd) << t.file;
    EXPECT_LT(first, 2.0 * recorded_sd) << t.file;
    const double holds = noise_in_holds(t).sd;  // the second path says the same
    EXPECT_GT(holds, 0.5 * recorded_sd) << t.file;
    EXPECT_LT(holds, 2.0 * recorded_sd) << t.file;
    if (&t == &d.tests.front())
      std::printf("[ figure ] quantised at %.0f Pa over noise of %.0f Pa: recorded about the truth %.0f Pa, first estimate %.0f Pa, holds %.0f Pa\n",
                  quantum, truth.noise_sd_pa, recorded_sd, first, noise_in_holds(t).sd);
  }
}

// A specimen run past its time limit stops with an error that says where it was; the analysis
// reports it and goes on with the material-point law (never a silent hang: the discs ran for 10
// CPU-minutes with no line).
TEST(SpecimenLimits, ARunPastItsTimeLimitStopsAndSaysWhere) {
  Truth truth;
  truth.tests = 2;
  const Dataset d = clot_like(truth);
  const MaterialModel m = analyze(d, {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0}).baseline.model;
  try {
    simulate_specimen(m, d, d.tests[0], nullptr, 1e-6);
    FAIL() << "a run with a microsecond to go finished";
  } catch (const viscera::tissue::SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("stopped at its time limit at t = "), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(simulate_specimen(m, d, d.tests[0], nullptr, 60.0));
}

// Several specimens in one data set (the discs were 4.37 and 3.78 mm thick): a test's own
// `specimen` in dataset.json replaces the data set's fields it names, survives writing and
// reading, is checked as the data set's is, and the specimen runs on each test's own geometry.
TEST(SpecimenLimits, EachTestRunsOnItsOwnSpecimen) {
  Truth truth;
  truth.tests = 2;
  Dataset d = clot_like(truth);
  d.tests[1].specimen = Specimen{0.02, 0.003, 0.003, 1050};
  const std::string folder = std::string(VISCERA_TEST_TMP) + "/two-specimens";
  write_dataset(d, folder);
  const Dataset back = read_dataset(folder);
  ASSERT_FALSE(back.tests[0].specimen.has_value());
  ASSERT_TRUE(back.tests[1].specimen.has_value());
  EXPECT_EQ(specimen_of(back, back.tests[1]).length_m, 0.02);
  EXPECT_EQ(specimen_of(back, back.tests[0]).length_m, 0.01);
  // A partial specimen takes the data set's other fields; a bad one is named with its test.
  std::string json;
  {
    std::ifstream in(folder + "/dataset.json");
    json.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto with = [&](const std::string& replacement) {
    std::string j = json;
    const auto at = j.find("\"specimen\"", j.find("s2.csv"));
    const auto end = j.find('}', at);
    j.replace(at, end + 1 - at, replacement);
    std::ofstream(folder + "/dataset.json") << j;
  };
  with(R"("specimen": {"thickness_m": 0.004})");
  const Dataset partial = read_dataset(folder);
  EXPECT_EQ(specimen_of(partial, partial.tests[1]).thickness_m, 0.004);
  EXPECT_EQ(specimen_of(partial, partial.tests[1]).length_m, 0.01);
  with(R"("specimen": {"length_m": -1})");
  try {
    read_dataset(folder);
    FAIL() << "a negative length was read";
  } catch (const viscera::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tests[1].specimen.length_m"), std::string::npos) << e.what();
  }
  // The specimen of each test: on a box twice as long the same material still misses the data by
  // what the law misses them (a homogeneous uniaxial stretch does not depend on the length).
  const MaterialModel m = analyze(d, {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0}).baseline.model;
  for (const auto& t : d.tests) {
    const SpecimenResult r = simulate_specimen(m, d, t);
    EXPECT_NEAR(r.rms_pa, rms_error_pa(m, t), 0.02 * rms_error_pa(m, t)) << t.file;
  }
}

// viscera-lab import: a test machine's export (force in mN, displacement in mm, tab separated,
// a byte-order mark) becomes a data set whose strain and stress are the hand conversion, with the
// conversion written into dataset.json; what cannot be right is named.
TEST(Import, APreloadAndAnotherZeroAreTakenOffWhenAsked) {
  Truth truth;
  truth.hold_s = 60.0;
  const Dataset direct = clot_like(truth);
  const std::string dir = std::string(VISCERA_TEST_TMP) + "/import_preload";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const double area = direct.specimen.width_m * direct.specimen.thickness_m, preload_pa = 400.0, zero_m = 0.7e-3;
  std::vector<std::string> files;
  for (const TestData& t : direct.tests) {
    files.push_back(dir + "/" + t.file);
    std::ofstream f(files.back());
    f.precision(12);
    f << "t,F,d\n";
    for (std::size_t i = 0; i < t.time_s.size(); ++i)
      f << t.time_s[i] << ',' << 1e3 * (t.stress_pa[i] + preload_pa) * area << ',' << 1e3 * (t.strain[i] * direct.specimen.length_m + zero_m) << '\n';
  }
  ImportOptions o;
  o.specimen = direct.specimen;
  o.time = parse_import_column("time", "t", ImportQuantity::time);
  o.force = parse_import_column("force", "F:mN", ImportQuantity::force);
  o.displacement = parse_import_column("displacement", "d:mm", ImportQuantity::displacement);
  o.tare = o.zero_displacement = true;
  const Dataset tared = import_dataset(files, o, dir + "/tared");
  ASSERT_EQ(tared.tests.size(), direct.tests.size());
  EXPECT_NEAR(tared.tests[0].stress_pa[0], 0.0, 1e-9);
  EXPECT_NEAR(tared.tests[0].strain[0], 0.0, 1e-12);
  // Taken off: the first row's force (preload plus the first sample's noise) and displacement.
  EXPECT_NE(tared.import_note.find("tare"), std::string::npos) << tared.import_note;
  EXPECT_NE(tared.import_note.find("displacement 0.0007 m"), std::string::npos) << tared.import_note;
  for (std::size_t k = 0; k < direct.tests.size(); ++k)
    for (std::size_t i = 0; i < direct.tests[k].time_s.size(); i += 97) {
      EXPECT_NEAR(tared.tests[k].strain[i], direct.tests[k].strain[i], 1e-9);
      EXPECT_NEAR(tared.tests[k].stress_pa[i], direct.tests[k].stress_pa[i] - direct.tests[k].stress_pa[0], 1e-6);
    }
  // Analysed, the imported tests are the generator's own with each test's first stress taken off
  // (in memory, another path): the same model, the same held-out error to the file's precision.
  // (The ramps start at once, one row at rest, so the tare carries the first sample's noise into
  // each test as an offset: the held-out error is a little above the generator's own data's.)
  Dataset shifted = direct;
  for (TestData& t : shifted.tests) {
    const double first = t.stress_pa[0];
    for (double& s : t.stress_pa) s -= first;
  }
  const AnalyzeOptions quick{.specimen = false, .nested = false, .bootstrap_replicates = 0};
  const Analysis a = analyze(direct, {}, quick), s = analyze(shifted, {}, quick), b = analyze(tared, {}, quick);
  std::printf("[ figure ] preload taken off: final held-out RMS %.3f Pa (in memory %.3f Pa, without any preload %.3f Pa); model '%s'\n",
              b.final.heldout_rms_pa, s.final.heldout_rms_pa, a.final.heldout_rms_pa, b.final.model.describe().c_str());
  EXPECT_EQ(b.final.model.describe(), s.final.model.describe());
  EXPECT_EQ(b.final.model.describe(), a.final.model.describe());
  EXPECT_NEAR(b.final.heldout_rms_pa, s.final.heldout_rms_pa, 1e-3 * s.final.heldout_rms_pa);
  // Without the tare the preload stays in the data: the same tests start at 400 Pa at zero strain.
  o.tare = false;
  const Dataset loaded = import_dataset(files, o, dir + "/loaded");
  const Analysis c = analyze(loaded, {}, quick);
  std::printf("[ figure ] preload left in: baseline held-out RMS %.1f Pa (with the tare %.1f Pa)\n", c.baseline.heldout_rms_pa,
              b.baseline.heldout_rms_pa);
  EXPECT_GT(c.baseline.heldout_rms_pa, 3 * b.baseline.heldout_rms_pa);
}

namespace {

/// Two discs (10 mm across, 4.37 and 3.78 mm thick) compressed in six steps of 10% to 60%, ramps at
/// 1 um/s, holds of 800 s, sampled at 1 Hz, forces quantised at 0.1 N (1.3 kPa) over 300 Pa of
/// noise, after a tare. The tissue: the first 4% of compression only takes up contact (a toe: no
/// stress), then an exponential stiffening in compression (E = 15 kPa, B = 4) beside one Maxwell
/// arm (40 kPa, 300 s). The toe lies outside the lab's catalogue.
Dataset disc_like() {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 300.0);
  Dataset d;
  d.name = "disc-like";
  d.folder = "generated";
  d.mode = Mode::uniaxial;
  const double area = 3.14159265358979 * 0.005 * 0.005, quantum = 0.1 / area, toe = 0.04, tau = 300.0, E = 15e3, B = 4.0, E1 = 40e3;
  d.specimen = {4.37e-3, 0.00886, 0.00886, 1050};  // a square of the disc's area
  int k = 0;
  for (const double thickness : {4.37e-3, 3.78e-3}) {
    TestData t;
    t.file = "disc" + std::to_string(++k) + ".csv";
    if (k == 2) t.specimen = Specimen{thickness, 0.00886, 0.00886, 1050};
    const double rate = 1e-6 / thickness, ramp = 0.1 / rate;  // strain per second, ramp time
    double eps = 0, q = 0, previous_load = 0, time = 0;
    for (int step = 0; step < 6; ++step)
      for (double s = 0; s < ramp + 800.0; s += 1.0, time += 1.0) {
        eps = -(0.1 * step + std::min(0.1, rate * s));
        const double load = std::min(0.0, eps + toe);  // compression past the toe
        if (time > 0) q = q * std::exp(-1.0 / tau) + E1 * (load - previous_load) * tau * (1 - std::exp(-1.0 / tau));
        previous_load = load;
        const double elastic = -(E / B) * std::expm1(-B * load);
        t.time_s.push_back(time);
        t.strain.push_back(eps);
        t.stress_pa.push_back(quantum * std::round((elastic + q + gauss(rng)) / quantum));
      }
    d.tests.push_back(std::move(t));
  }
  return d;
}

}  // namespace

TEST(OtherLabs, DiscLikeCompressionToSixtyPercent) {
  const Dataset d = disc_like();
  const auto t0 = std::chrono::steady_clock::now();
  const Analysis a = analyze(d, {}, {.specimen = false});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("[ figure ] disc-like: %s\n", a.verdict.c_str());
  std::printf(
      "[ figure ] disc-like: baseline held-out %.0f Pa, final %.0f Pa (%s), nested %.0f Pa (gain %.2f, %s), noise %.0f Pa / holds %.0f Pa, "
      "adequacy %s (%.1fx the noise), %.1f s\n",
      a.baseline.heldout_rms_pa, a.final.heldout_rms_pa, a.final.model.describe().c_str(), a.nested_heldout_rms_pa, a.nested_gain,
      a.nested_not_run.c_str(), a.noise_pa, a.noise_check.holds_pa, a.adequacy.explained ? "explained" : "not explained",
      a.adequacy.residual_to_noise, seconds);
  for (const auto& f : a.adequacy.findings) std::printf("[ figure ]   %s\n", f.c_str());
  // Done within seconds (the material-point law; the specimen's limits are tested above).
  EXPECT_LT(seconds, 60.0);
  // The truth's two mechanisms, both above the noise, named; nothing else. With two tests the
  // honest gain cannot be measured: tentative, and said why.
  const auto named = a.named_causes();
  const auto has = [&](Mechanism m) { return std::find(named.begin(), named.end(), m) != named.end(); };
  EXPECT_TRUE(has(Mechanism::strain_stiffening));
  EXPECT_TRUE(has(Mechanism::broadband_relaxation));
  EXPECT_FALSE(has(Mechanism::tension_compression_asymmetry));
  EXPECT_FALSE(has(Mechanism::first_load_softening));
  EXPECT_EQ(a.causes_status, CausesStatus::tentative);
  EXPECT_NE(a.nested_not_run.find("at least 3"), std::string::npos) << a.nested_not_run;
  // The final model predicts each disc from the other within twice the noise, several times
  // better than the linear baseline. (The 4% toe gives at most 600 Pa, under the 1.3 kPa quantum:
  // the data cannot show it, and the verdict rightly does not claim it.)
  EXPECT_LT(a.final.heldout_rms_pa, 2.0 * a.noise_pa);
  EXPECT_GT(a.baseline.heldout_rms_pa, 3.0 * a.final.heldout_rms_pa);
}

// Fast ramps sampled fast and long holds sampled slowly in one test (a logger that thins its rate
// once the machine holds): 100 Hz over the ramps, one sample every 10 s over holds of an hour.
TEST(OtherLabs, FastRampsAndSlowHoldsInOneTest) {
  Truth truth;
  truth.rate_hz = 100.0;
  truth.hold_rate_hz = 0.1;
  truth.hold_s = 3600.0;
  const Dataset d = clot_like(truth);
  const Analysis a = analyze(d, {}, kWithoutSpecimen);
  std::printf("[ figure ] fast ramps, slow holds: %s\n", a.verdict.c_str());
  std::printf(
      "[ figure ] fast ramps, slow holds: baseline held-out %.1f Pa, final %.1f Pa, nested gain %.2f, noise %.2f Pa / holds %.2f Pa "
      "(window %.1f s), adequacy %s (%.2fx)\n",
      a.baseline.heldout_rms_pa, a.final.heldout_rms_pa, a.nested_gain, a.noise_pa, a.noise_check.holds_pa, a.noise_check.window_s,
      a.adequacy.explained ? "explained" : "not explained", a.adequacy.residual_to_noise);
  const auto named = a.named_causes();
  EXPECT_NE(std::find(named.begin(), named.end(), Mechanism::broadband_relaxation), named.end());
  EXPECT_EQ(a.causes_status, CausesStatus::confirmed);
  EXPECT_GT(a.noise_pa, 0.5 * truth.noise_sd_pa);
  EXPECT_LT(a.noise_pa, 2.0 * truth.noise_sd_pa);
  EXPECT_TRUE(a.noise_check.agree);
  EXPECT_TRUE(a.adequacy.explained);
}

// The discs on the meshed specimen, to 60% compression. They used to stop at 20% ("implicit step
// did not converge"): the tangent took the memory's tension times the relaxed share and the
// Kelvin-Voigt rate, and Newton's steps stopped descending. Now both models run to the end, and the
// report says where the specimen leaves the material-point law: the GPS, linear in its edge
// elongations, softens under large compression (its reaction peaks near 30% and reverses by 60%
// here), which the 1D law does not.
TEST(OtherLabs, DiscLikeRunsOnTheSpecimenToSixtyPercentAndSaysWhereItLeavesTheLaw) {
  const Dataset d = disc_like();
  const Analysis a = analyze(d, {}, {.max_fit_points = 800, .bootstrap_replicates = 0});
  ASSERT_EQ(a.specimen.size(), 2u);
  for (const auto& c : a.specimen) {
    std::printf("[ figure ] disc-like on the specimen, %s: %s\n", c.model.c_str(), c.note.c_str());
    for (std::size_t k = 0; k < c.files.size(); ++k)
      std::printf("[ figure ]   %s: specimen %.0f Pa, law %.0f Pa RMS\n", c.files[k].c_str(), c.specimen_rms_pa[k], c.law_rms_pa[k]);
    EXPECT_TRUE(c.ran) << c.note;
    EXPECT_EQ(c.files.size(), d.tests.size());
    const std::string said = "first leaves the law by more than a tenth of the largest stress at strain ";
    const auto at = c.note.find(said);
    ASSERT_NE(at, std::string::npos) << c.note;
    const double strain = std::stod(c.note.substr(at + said.size()));
    EXPECT_LT(strain, -0.15) << c.note;
    EXPECT_GT(strain, -0.45) << c.note;
  }
}
