// viscera-lab must find the effect hidden in synthetic data (or none), seeing only the folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "analysis.hpp"
#include "synthetic_data.hpp"

using namespace viscera::lab;

TEST(HiddenEffect, NamedCorrectlyIn95PercentOf40SeedsWithGainAboveNoise) {
  const std::string root = std::string(VISCERA_TEST_TMP) + "/synthetic";
  int correct = 0, total = 0;
  std::map<std::string, int> wrong;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const std::string folder = root + "/seed_" + std::to_string(seed);
    std::filesystem::remove_all(folder);
    const test::Truth truth = test::write_synthetic_dataset(seed, folder);
    const Analysis a = analyze(read_dataset(folder));  // the lab sees only the folder
    const std::string expected = test::effect_name(truth.effect);
    std::string found = a.causes.empty() ? "none" : name(a.causes.front());
    const bool ok = (truth.effect == test::Effect::none) ? a.causes.empty() : (a.causes.size() == 1 && found == expected);
    ++total;
    if (ok) ++correct;
    else wrong[expected + " -> " + found + (a.causes.size() > 1 ? " (+more)" : "")]++;
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
