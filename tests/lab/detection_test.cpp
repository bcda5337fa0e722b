// viscera-lab must find the effect hidden in synthetic data (or none), seeing only the folder.  // SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "viscera/lab/analysis.hpp"
#include "viscera/lab/specimen_simulation.hpp"
#include "viscera/lab/stress_controlled.hpp"
#include "viscera/lab/synthetic_data.hpp"

using namespace viscera::lab;

TEST(HiddenEffect, NamedCorrectlyIn95PercentOf40SeedsWithGainAboveNoise) {
  const std::string root = std::string(VISCERA_TEST_TMP) + "/synthetic";
  int correct = 0, total = 0;
  std::map<std::string, int> wrong;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const std::string folder = root + "/seed_" + std::to_string(seed);
    std::filesystem::remove_all(folder);
    const test::Truth truth = test::write_synthetic_dataset(seed, folder);
    const Analysis a =
        analyze(read_dataset(folder), {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0});  // the lab sees only the folder
    const std::string expected = test::effect_name(truth.effect);
    std::string found = a.causes.empty() ? "none" : name(a.causes.front());
    const bool ok = (truth.effect == test::Effect::none) ? a.causes.empty() : (a.causes.size() == 1 && found == expected);
    ++total;
    if (ok)
      ++correct;
    else
      // NOLINTNEXTLINE(performance-inefficient-string-concatenation): a test's message, once per seed
      wrong[expected + " -> " + found + (a.causes.size() > 1 ? " (+more)" : "")]++;
    if (!a.causes.empty()) {
      // A named cause must come with a held-out gain above noise.
      const double reduction = a.baseline.heldout_rms_pa * a.baseline.heldout_rms_pa - a.final.heldout_rms_pa * a.final.heldout_rms_pa;
      EXPECT_GT(reduction, 0.5 * a.noise_pa * a.noise_pa) << "seed " << seed;
    }
    std::cout << "[ seed " << seed << " ] hidden " << expected << ", found";
    for (Mechanism m : a.causes) std::cout << " " << name(m);
    if (a.causes.empty()) std::cout << " none";
    std::cout << "; held-out RMS " << a.baseline.heldout_rms_pa << " -> " << a.final.heldout_rms_pa << " Pa, noise " << a.noise_pa << " Pa\n";
  }
  std::cout << "[ figure ] hidden effect named correctly in " << correct << " of " << total << " seeds\n";
  for (const auto& [k, v] : wrong) std::cout << "  wrong: " << k << " x" << v << "\n";
  EXPECT_GE(correct, 38);  // 95% of 40
}

TEST(HiddenEffect, ContinuousPowerLawRelaxationOutsideTheFamilyIsNamedBroadband) {
  // The truth relaxes as (1 + t/tau0)^-alpha, which no finite set of memory variables equals:
  // the lab must still name broadband relaxation (alone) with a held-out gain above noise.
  const std::string root = std::string(VISCERA_TEST_TMP) + "/power_law";
  int correct = 0;
  const int total = 10;
  for (unsigned seed = 1; seed <= total; ++seed) {
    const std::string folder = root + "/seed_" + std::to_string(seed);
    std::filesystem::remove_all(folder);
    const test::Truth truth = test::write_power_law_dataset(seed, folder);
    const Analysis a = analyze(read_dataset(folder), {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0});
    const bool ok = a.causes.size() == 1 && a.causes.front() == Mechanism::broadband_relaxation;
    correct += ok;
    std::cout << "[ power-law seed " << seed << " ] alpha " << truth.power_alpha << ", tau0 " << truth.power_tau0_s << " s: found";
    for (Mechanism m : a.causes) std::cout << " " << name(m);
    if (a.causes.empty()) std::cout << " none";
    std::cout << "; held-out RMS " << a.baseline.heldout_rms_pa << " -> " << a.final.heldout_rms_pa << " Pa, noise " << a.noise_pa << " Pa\n";
    if (!a.causes.empty()) {
      const double reduction = a.baseline.heldout_rms_pa * a.baseline.heldout_rms_pa - a.final.heldout_rms_pa * a.final.heldout_rms_pa;
      EXPECT_GT(reduction, 0.5 * a.noise_pa * a.noise_pa) << "seed " << seed;
    }
  }
  std::cout << "[ figure ] continuous power-law relaxation named broadband_relaxation in " << correct << " of " << total << " seeds\n";
  EXPECT_GE(correct, 9);
}

TEST(StiffeningForms, OgdensFormIsNeoHookeanAtExponent2AndOddInShear) {
  // At exponent 2 a one-term incompressible Ogden solid is neo-Hookean: uniaxial nominal stress
  // mu (l - l^-2) (E = 3 mu), simple-shear stress mu g, exactly linear. The lab's form, normalised
  // to slope 1, against those closed forms; in shear odd at any exponent; slope 1 at rest.
  MaterialModel m;
  m.mechanisms = 1u << static_cast<unsigned>(Mechanism::strain_stiffening);
  m.stiffening_form = StiffeningForm::ogden;
  m.stiffening_b = 2.0;
  for (const double e : {-0.4, -0.1, 0.05, 0.3}) {
    m.odd_only = false;
    EXPECT_NEAR(ElasticShape{m}.value(e), ((1 + e) - 1 / ((1 + e) * (1 + e))) / 3, 1e-14) << e;
    m.odd_only = true;
    EXPECT_NEAR(ElasticShape{m}.value(e), e, 1e-14) << e;
  }
  for (const double a : {0.5, 8.0, 25.0})
    for (const bool shear : {false, true}) {
      m.stiffening_b = a;
      m.odd_only = shear;
      const double h = 1e-6;
      EXPECT_NEAR((ElasticShape{m}.value(h) - ElasticShape{m}.value(-h)) / (2 * h), 1.0, 1e-8) << a;
      if (shear) {
        EXPECT_NEAR(ElasticShape{m}.value(-0.2), -ElasticShape{m}.value(0.2), 1e-12) << a;
      }
    }
}

TEST(Specimen, TetrahedralSpecimenAgreesWithTheMaterialPointLaw) {
  // Two code paths for the same model: the GPS on a meshed specimen (implicit, inertia, memory
  // variables) and the lab's material-point law, each run along the test's command path: their
  // histories of the measured quantity (stress under strain control, strain under stress control)
  // agree, as a relative RMS difference.
  for (unsigned seed : {1u, 5u, 7u}) {  // broadband; baseline; strain stiffening, uniaxial (energy form, calibrated B)
    const std::string folder = std::string(VISCERA_TEST_TMP) + "/specimen_" + std::to_string(seed);
    std::filesystem::remove_all(folder);
    test::write_synthetic_dataset(seed, folder);
    const Dataset d = read_dataset(folder);
    const Analysis a = analyze(d);
    ASSERT_FALSE(a.specimen.empty());
    for (const auto& c : a.specimen) ASSERT_TRUE(c.ran) << c.note;
    std::vector<MaterialModel> models{a.baseline.model};
    if (!a.causes.empty()) models.push_back(a.final.model);
    for (const MaterialModel& m : models) {
      const ShapeCalibration calibration = calibrate_elastic_shape(m, d);
      for (const auto& t : d.tests) {
        const SpecimenResult r = simulate_specimen(m, d, t, &calibration);
        const bool creep = t.control == Control::stress;
        const std::vector<double> law = predict_measured(m, t), specimen = creep ? r.strain : r.stress_pa;
        double diff = 0.0, norm = 0.0;
        for (std::size_t k = 0; k < law.size(); ++k) {
          diff += (specimen[k] - law[k]) * (specimen[k] - law[k]);
          norm += law[k] * law[k];
        }
        const double relative = std::sqrt(diff / norm);
        std::cout << "[ figure ] seed " << seed << " " << m.describe() << " " << t.file << ": specimen against the law, RMS difference "
                  << 100 * relative << "% of the law's RMS " << (creep ? "strain" : "stress") << "\n";
        // Linear models agree to 0.1% (both are exact along the path but for the specimen's time
        // steps); a shaped model's specimen constant is calibrated on static curves (2-4% apart
        // in time); creep on the specimen is backward Euler through the strain's transients (1-3%).
        const bool shaped = m.has(Mechanism::strain_stiffening) || m.has(Mechanism::tension_compression_asymmetry);
        EXPECT_LT(relative, creep || shaped ? 0.05 : 0.005) << t.file;
      }
    }
  }
}

namespace {
/// A synthetic data set whose final model has `mechanism`: the model fitted by the lab (which
/// sees only the folder), its specimen calibration, and each strain-controlled test's specimen
/// stress history against the law's (relative RMS difference), printed as figures.
struct ShapeCheck {
  ShapeCalibration calibration;
  std::vector<double> history_difference;
};
ShapeCheck check_shape_on_specimen(unsigned seed, Mechanism mechanism, Mode mode) {
  const std::string folder = std::string(VISCERA_TEST_TMP) + "/shape_" + std::to_string(seed);
  std::filesystem::remove_all(folder);
  test::write_synthetic_dataset(seed, folder);
  const Dataset d = read_dataset(folder);
  EXPECT_EQ(d.mode, mode);
  const MaterialModel m = analyze(d, {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0}).final.model;
  EXPECT_TRUE(m.has(mechanism)) << m.describe();
  ShapeCheck check{calibrate_elastic_shape(m, d), {}};
  const auto& c = check.calibration;
  std::cout << "[ figure ] seed " << seed << " (" << name(m.stiffening_form) << "): law B " << c.law_b << " r " << c.law_r << ", specimen B "
            << c.gps_b << " r " << c.gps_r << ": elastic curves differ by " << 100 * c.uncalibrated_mismatch << "% with the law's constants, "
            << 100 * c.mismatch << "% calibrated\n";
  for (const auto& t : d.tests) {
    if (t.control != Control::strain) continue;
    const SpecimenResult r = simulate_specimen(m, d, t, &c);
    const auto law = predict_stress(m, t);
    double diff = 0.0, norm = 0.0;
    for (std::size_t k = 0; k < law.size(); ++k) {
      diff += (r.stress_pa[k] - law[k]) * (r.stress_pa[k] - law[k]);
      norm += law[k] * law[k];
    }
    check.history_difference.push_back(std::sqrt(diff / norm));
    std::cout << "[ figure ] " << t.file << ": specimen stress vs the law's, RMS difference " << 100 * check.history_difference.back()
              << "% of the law's RMS stress; " << r.steps << " steps, " << r.step_cuts << " step cuts\n";
  }
  return check;
}

/// The calibration matched the law's elastic curve better than without it, to `max_mismatch`, and
/// every strain-controlled stress history on the specimen is within `max_history` of the law's.
void expect_reproduced(const ShapeCheck& check, double max_mismatch, double max_history) {
  EXPECT_LT(check.calibration.mismatch, max_mismatch);
  EXPECT_LT(check.calibration.mismatch, check.calibration.uncalibrated_mismatch);
  ASSERT_FALSE(check.history_difference.empty());
  for (const double diff : check.history_difference) EXPECT_LT(diff, max_history);
}
}  // namespace

TEST(Specimen, AsymmetryRunsInItsEnergyFormUniaxially) {
  // Seed 3 hides tension/compression asymmetry in uniaxial data: the calibrated compression ratio
  // on the specimen reproduces the law's stress history on every strain-controlled test to within
  // 8%. Not exactly: a specimen whose compressed edges are stiffer than its stretched ones softens
  // under finite compression (at r = 2.46 the secant ratio falls from 2.45 at 2% to 2.19 at 14%
  // compression; at r = 1 or 0.4 it stays within 0.5%), which one constant cannot follow.
  expect_reproduced(check_shape_on_specimen(3, Mechanism::tension_compression_asymmetry, Mode::uniaxial), 0.06, 0.08);
}

TEST(Specimen, StiffeningRunsInItsEnergyFormUniaxiallyAndInShear) {
  // Uniaxial (seed 7): the GPS's conservative form with its calibrated B reproduces the law's
  // stress history on every strain-controlled test (not just its RMS against the data), with
  // Newton converging at every step (it stalled near B e = 1 with the edge map).
  expect_reproduced(check_shape_on_specimen(7, Mechanism::strain_stiffening, Mode::uniaxial), 0.02, 0.05);
  // Simple shear (seed 2, an odd exponential truth): the lab offers only odd stiffening forms in
  // shear (an isotropic solid's shear stress is odd in the shear strain), and the GPS runs them in
  // its energy form.
  const ShapeCheck shear = check_shape_on_specimen(2, Mechanism::strain_stiffening, Mode::simple_shear);
  expect_reproduced(shear, 0.05, 0.08);
}

TEST(Specimen, StrongStiffeningIsStableOnTheSpecimenUpToBTimesStrainOf4To6) {
  // Strong stiffening on the meshed specimen (energy form, static Newton solves from the last
  // state, halving the increment where Newton stalls) against the closed-form 1D law, B
  // calibrated on the tension side. Measured limits, each form where it is physical:
  //  - uniaxial tension to strain 0.2: Fung's exponential to B e = 4 (at 5 the laterally compressed
  //    edges, on the exponential's flat side, are thousands of times softer than the stretched ones
  //    and Newton stalls), the odd exponential to 5, the odd polynomial to 6;
  //  - simple shear to +-0.2 (the odd forms only): both to B e = 6.
  // Uniaxial compression with an odd law is not compared: a compressed specimen's lateral edges
  // stretch and stiffen too, so its curve is not the 1D law's (34-58% apart at B e = 3-5).
  struct Case {
    Mode mode;
    StiffeningForm form;
    double b, lowest_strain, max_mismatch;
  };
  for (const Case& c :
       {Case{Mode::uniaxial, StiffeningForm::exponential, 20.0, 0.0, 0.02}, Case{Mode::uniaxial, StiffeningForm::odd_exponential, 25.0, 0.0, 0.02},
        Case{Mode::uniaxial, StiffeningForm::odd_polynomial, 30.0, 0.0, 0.02},
        Case{Mode::simple_shear, StiffeningForm::odd_exponential, 30.0, -0.2, 0.15},
        Case{Mode::simple_shear, StiffeningForm::odd_polynomial, 30.0, -0.2, 0.05}}) {
    Dataset d;
    d.mode = c.mode;
    d.specimen = {0.01, 0.01, 0.003, 1050};
    TestData t;
    t.time_s = {0, 1, 2};
    t.strain = {0.0, 0.2, c.lowest_strain};
    t.stress_pa = {0, 1, -1};
    d.tests = {t};
    MaterialModel m;
    m.mechanisms = 1u << static_cast<unsigned>(Mechanism::strain_stiffening);
    m.stiffening_form = c.form;
    m.stiffening_b = c.b;
    m.modulus_pa = 1e4;
    std::string why;
    ASSERT_TRUE(specimen_supports(m, d.mode, &why)) << why;
    ShapeCalibration k;
    ASSERT_NO_THROW(k = calibrate_elastic_shape(m, d)) << name(c.form);
    std::cout << "[ figure ] " << to_string(c.mode) << " " << name(c.form) << ", law B " << c.b << " (B e = " << 0.2 * c.b << "): specimen B "
              << k.gps_b << ", curves over strains " << c.lowest_strain << "..0.2 differ by " << 100 * k.uncalibrated_mismatch
              << "% with the law's B, " << 100 * k.mismatch << "% calibrated\n";
    EXPECT_LT(k.mismatch, c.max_mismatch) << to_string(c.mode) << " " << name(c.form);
  }
}

TEST(Specimen, FirstLoadSofteningRunsPerEdgeInBothModes) {
  // Seeds 9 (uniaxial) and 4 (simple shear) hide first-load softening. On the specimen each edge
  // keeps its own extremes (GpsSoftening); under the mode's
  // proportional loading every edge's |e| / m is the specimen's, so what the softening changes in
  // the specimen's stress history (the fitted model against the same model with d = 0) must be
  // what it changes in the law's, on every strain-controlled test with reloading. Uniaxially the
  // whole history must also be the law's; in simple shear the specimen differs from the linear law
  // by 3-8% with or without the softening (finite shear of 12% on the meshed specimen), so there
  // only the softening's part is compared.
  const auto rms = [](const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) s += (a[k] - (b.empty() ? 0.0 : b[k])) * (a[k] - (b.empty() ? 0.0 : b[k]));
    return std::sqrt(s / static_cast<double>(a.size()));
  };
  for (const unsigned seed : {9u, 4u}) {
    const std::string folder = std::string(VISCERA_TEST_TMP) + "/softening_" + std::to_string(seed);
    std::filesystem::remove_all(folder);
    test::write_synthetic_dataset(seed, folder);
    const Dataset d = read_dataset(folder);
    const MaterialModel m = analyze(d, {}, {.specimen = false, .bootstrap_replicates = 0}).final.model;
    ASSERT_TRUE(m.has(Mechanism::first_load_softening)) << m.describe();
    std::string why;
    ASSERT_TRUE(specimen_supports(m, d.mode, &why)) << why;
    MaterialModel virgin = m;
    virgin.softening_d = 0.0;
    int reloading = 0;
    for (const auto& t : d.tests) {
      if (t.control != Control::strain) continue;
      const auto law = predict_stress(m, t), law_virgin = predict_stress(virgin, t);
      const auto spec = simulate_specimen(m, d, t).stress_pa, spec_virgin = simulate_specimen(virgin, d, t).stress_pa;
      std::vector<double> law_effect(law.size()), spec_effect(law.size());
      for (std::size_t k = 0; k < law.size(); ++k) {
        law_effect[k] = law[k] - law_virgin[k];
        spec_effect[k] = spec[k] - spec_virgin[k];
      }
      const double effect = rms(law_effect, {}) / rms(law, {});
      const double history_error = rms(spec, law) / rms(law, {});
      if (effect < 0.05) continue;  // monotonic ramps: only the noise dips below the extreme
      const double effect_error = rms(spec_effect, law_effect) / rms(law_effect, {});
      std::cout << "[ figure ] seed " << seed << " (" << (d.mode == Mode::uniaxial ? "uniaxial" : "simple shear") << ", d = " << m.softening_d << ") "
                << t.file << ": the softening changes the law's stress by " << 100 * effect << "% RMS; the specimen's change differs from that by "
                << 100 * effect_error << "% of it; specimen vs law " << 100 * history_error << "%\n";
      ++reloading;
      EXPECT_LT(effect_error, 0.10) << t.file;
      if (d.mode == Mode::uniaxial) {
        EXPECT_LT(history_error, 0.03) << t.file;
      }
    }
    EXPECT_GE(reloading, 2) << "seed " << seed;
  }
}
