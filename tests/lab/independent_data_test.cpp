// viscera-lab on data it has never seen (issue 23): data sets from lab_protocols.hpp, whose  // SPDX-License-Identifier: Apache-2.0
// truths, protocols and forms were written outside the lab (linear damping on the strain rate;
// symmetric polynomial stiffening, softening that recovers at rest and power-law relaxation
// outside the lab's forms; creep-recovery under stress control; non-uniform sampling; no noise
// column in every third set). The lab sees only the folder. A sample small enough for every run;
// bench/lab_accuracy measures the full table in docs/LAB.md.
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>

#include "viscera/lab/analysis.hpp"
#include "viscera/lab/lab_protocols.hpp"

using namespace viscera::lab;

namespace {

Analysis analyze_truth(test::LabTruth truth, unsigned seed) {
  const std::string folder = std::string(VISCERA_TEST_TMP) + "/independent/" + test::name(truth) + "_" + std::to_string(seed);
  std::filesystem::remove_all(folder);
  test::write_lab_dataset(seed, truth, 1.0, folder);
  return analyze(read_dataset(folder), {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0});
}

}  // namespace

// Every truth here lies inside the lab's catalogue of causes (some outside its forms): the
// adequacy verdict must say the final model explains the data on at least 95% of the sets.
TEST(IndependentData, CausesAreNamedAtTodaysSizesInsideAndOutsideTheLabsForms) {
  int in_right = 0, in_total = 0, out_right = 0, out_total = 0, unexplained = 0;
  for (test::LabTruth truth :
       {test::LabTruth::exponential_stiffening, test::LabTruth::polynomial_stiffening, test::LabTruth::asymmetry, test::LabTruth::softening,
        test::LabTruth::recovering_softening, test::LabTruth::broadband, test::LabTruth::power_law, test::LabTruth::broadband_and_stiffening})
    for (unsigned seed = 1; seed <= 4; ++seed) {
      const Analysis a = analyze_truth(truth, seed);
      const bool right = test::names_expected_causes(truth, a.causes);
      (test::out_of_family(truth) ? out_right : in_right) += right;
      (test::out_of_family(truth) ? out_total : in_total) += 1;
      std::cout << "[ " << test::name(truth) << " seed " << seed << " ] named";
      for (Mechanism m : a.causes) std::cout << " " << name(m);
      std::cout << (a.causes.empty() ? " none" : "") << (right ? "" : "  <- wrong") << "; residual " << a.adequacy.residual_to_noise << "x the noise"
                << (a.adequacy.explained ? "" : ", not explained  <- flagged") << "\n";
      unexplained += !a.adequacy.explained;
    }
  std::cout << "[ figure ] in the lab's forms: " << in_right << " of " << in_total << "; outside them: " << out_right << " of " << out_total << "\n";
  std::cout << "[ figure ] in the catalogue, said not to be explained: " << unexplained << " of " << in_total + out_total << "\n";
  EXPECT_LE(unexplained, (in_total + out_total) * 5 / 100);
  EXPECT_GE(in_right, in_total * 85 / 100);
  EXPECT_GE(out_right, out_total * 75 / 100);
}

TEST(IndependentData, AtMostOneFalsePositiveIn20KelvinVoigtSets) {
  int named = 0, unexplained = 0;
  for (unsigned seed = 101; seed <= 120; ++seed) {
    const Analysis a = analyze_truth(test::LabTruth::none, seed);
    unexplained += !a.adequacy.explained;
    if (!a.causes.empty()) {
      ++named;
      std::cout << "[ none seed " << seed << " ] named " << name(a.causes.front()) << "\n";
    }
  }
  std::cout << "[ figure ] causes named on " << named << " of 20 Kelvin-Voigt sets; said not to be explained on " << unexplained << "\n";
  EXPECT_LE(named, 1);
  EXPECT_LE(unexplained, 1);
}

// Issue 60: the generator's tests are one session on one specimen, and a softened specimen stays
// softened from one test to the next. Judged with the history intact (each held-out test
// predicted in its place in the session), first-load softening must be named on its honest gain
// (the nested leave-one-out decides); the Kelvin-Voigt sessions must name nothing. Beside it, the
// same sets with the lab blind to the history (every test taken to start untouched).
TEST(IndependentData, FirstLoadSofteningCarriedThroughASessionIsNamedOnItsHonestGain) {
  constexpr unsigned kSeeds = 4;
  int right = 0, right_blind = 0, false_named = 0;
  for (test::LabTruth truth : {test::LabTruth::softening, test::LabTruth::none})
    for (unsigned seed = 201; seed < 201 + kSeeds; ++seed) {
      const std::string folder = std::string(VISCERA_TEST_TMP) + "/history/" + test::name(truth) + "_" + std::to_string(seed);
      std::filesystem::remove_all(folder);
      test::write_lab_dataset(seed, truth, 1.0, folder);
      Dataset d = read_dataset(folder);
      ASSERT_EQ(d.history, History::carried);
      for (int blind = 0; blind < 2; ++blind) {
        d.history = blind ? History::reset : History::carried;
        const Analysis a = analyze(d, {}, {.specimen = false, .nested = true, .bootstrap_replicates = 0});
        const bool ok = test::names_expected_causes(truth, a.named_causes());
        std::cout << "[ " << test::name(truth) << " seed " << seed << (blind ? ", blind to history" : "") << " ] named";
        for (Mechanism m : a.named_causes()) std::cout << " " << name(m);
        std::cout << (a.named_causes().empty() ? " none" : "") << " (" << to_string(a.causes_status) << ", honest gain " << a.nested_gain << "x)"
                  << (ok ? "" : "  <- wrong") << "\n";
        if (truth == test::LabTruth::softening) (blind ? right_blind : right) += ok;
        if (truth == test::LabTruth::none && !blind) false_named += !ok;
      }
    }
  std::cout << "[ figure ] softening named on its honest gain: " << right << " of " << kSeeds << " with the history, " << right_blind << " of "
            << kSeeds << " blind to it; causes named on " << false_named << " of " << kSeeds << " Kelvin-Voigt sessions\n";
  EXPECT_EQ(right, static_cast<int>(kSeeds));
  EXPECT_EQ(false_named, 0);
}
