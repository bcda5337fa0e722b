// viscera-lab's accuracy on data it has never seen (issue 23): data sets from tests/lab's  // SPDX-License-Identifier: Apache-2.0
// independent generator (lab_protocols.hpp), one truth each, at today's effect sizes and at 0.3x
// and 0.1x; the lab sees only the folder. Prints the accuracy per truth and size, the confusion
// between causes and the false-positive rate on the "none" sets, as Markdown (docs/LAB.md).
// With --adequacy, the adequacy verdict instead (issue 36): how often the final model is said not to
// explain the data, on truths inside the catalogue (should be rare) and outside it (permanent set,
// instrument drift, rate thinning, grip slip: should be nearly always), seeds from --first-seed.
// With --history, the honest gain's causes on sessions whose history carries (issue 60).
//   lab_accuracy [--seeds N] [--none N] [--dir DIR] [--adequacy | --history] [--first-seed K]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "viscera/lab/analysis.hpp"
#include "viscera/lab/lab_protocols.hpp"

using namespace viscera::lab;

namespace {

std::string causes_of(const Analysis& a) {
  std::string s;
  for (Mechanism m : a.causes) s += (s.empty() ? "" : " + ") + std::string(name(m));
  return s.empty() ? "none" : s;
}

/// The adequacy table: per truth, on how many sets the final model was said not to explain the data.
void adequacy_table(const std::function<Analysis(test::LabTruth, double, unsigned)>& run, int seeds, int first_seed) {
  std::printf("| truth | in the catalogue | said not explained | residual / noise (min - max) |\n|---|---|---|---|\n");
  int flagged[2] = {0, 0}, total[2] = {0, 0};
  for (int t = 0; t <= static_cast<int>(test::LabTruth::grip_slip); ++t) {
    const auto truth = static_cast<test::LabTruth>(t);
    const bool outside = test::out_of_catalogue(truth);
    int n = 0;
    double lo = 1e300, hi = 0;
    for (int s = first_seed; s < first_seed + seeds; ++s) {
      const Analysis a = run(truth, 1.0, static_cast<unsigned>(s));
      n += !a.adequacy.explained;
      lo = std::min(lo, a.adequacy.residual_to_noise);
      hi = std::max(hi, a.adequacy.residual_to_noise);
    }
    flagged[outside] += n;
    total[outside] += seeds;
    std::printf("| %s | %s | %d of %d | %.2f - %.2f |\n", test::name(truth), outside ? "no" : "yes", n, seeds, lo, hi);
    std::fflush(stdout);
  }
  std::printf("\nInside the catalogue: said not explained on %d of %d sets; outside it: on %d of %d.\n", flagged[0], total[0], flagged[1], total[1]);
}

/// The history table (issue 60): per truth, how often the causes named on the honest gain (the
/// nested leave-one-out decides) are the truth's, with the session simulated in its order, and
/// with the lab blind to it (every test taken to start on an untouched specimen).
void history_table(const std::function<Dataset(test::LabTruth, unsigned)>& generate, int seeds, int first_seed) {
  std::printf("| truth | named right, history carried | named right, blind to history | named instead (carried) |\n|---|---|---|---|\n");
  for (test::LabTruth truth : {test::LabTruth::softening, test::LabTruth::recovering_softening, test::LabTruth::none,
                               test::LabTruth::exponential_stiffening, test::LabTruth::asymmetry, test::LabTruth::broadband}) {
    int right[2] = {0, 0};
    std::map<std::string, int> instead;
    for (int s = first_seed; s < first_seed + seeds; ++s) {
      Dataset d = generate(truth, static_cast<unsigned>(s));
      for (int blind = 0; blind < 2; ++blind) {
        d.history = blind ? History::reset : History::carried;
        Analysis a = analyze(d, {}, {.specimen = false, .nested = true, .bootstrap_replicates = 0});
        a.causes = a.named_causes();
        const bool ok = test::names_expected_causes(truth, a.causes);
        right[blind] += ok;
        if (!blind && !ok) ++instead[causes_of(a)];
      }
    }
    std::string other;
    for (const auto& [k, v] : instead) other += (other.empty() ? "" : ", ") + k + " (" + std::to_string(v) + ")";
    std::printf("| %s | %d of %d | %d of %d | %s |\n", test::name(truth), right[0], seeds, right[1], seeds, other.c_str());
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 20, nones = 100, first_seed = 1;
  bool adequacy = false, history = false;
  std::string dir = (std::filesystem::temp_directory_path() / "viscera_lab_accuracy").string();
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--adequacy") {
      adequacy = true;
      continue;
    }
    if (a == "--history") {
      history = true;
      continue;
    }
    if (a == "--help" || a == "-h") {
      std::printf(
          "Usage: lab_accuracy [--seeds N] [--none N] [--dir DIR] [--adequacy | --history] [--first-seed K]\n"
          "Runs viscera-lab on data sets from the independent generator of tests/lab (N seeds per truth and effect size,\n"
          "and N 'none' sets) and prints accuracy per truth, the confusion between causes and the false-positive rate\n"
          "as Markdown. Defaults: 20 seeds, 100 none sets, data sets written under the system's temporary folder.\n"
          "--adequacy: instead, per truth inside and outside the catalogue of causes, how often the final model is said not to\n"
          "explain the data (N seeds from K, default 1).\n"
          "--history: instead, per truth (first-load softening, and causes without history as controls), how often the causes\n"
          "named on the honest gain (nested leave-one-out) are right, the session simulated in its order against the lab blind\n"
          "to it (N seeds from K).\n");
      return 0;
    }
    if (k + 1 >= argc) {
      std::fprintf(stderr, "lab_accuracy: %s needs a value (see --help)\n", a.c_str());
      return 2;
    }
    const std::string v = argv[++k];
    if (a == "--seeds")
      seeds = std::atoi(v.c_str());
    else if (a == "--none")
      nones = std::atoi(v.c_str());
    else if (a == "--dir")
      dir = v;
    else if (a == "--first-seed")
      first_seed = std::atoi(v.c_str());
    else {
      std::fprintf(stderr, "lab_accuracy: unknown option %s (see --help)\n", a.c_str());
      return 2;
    }
    if ((a == "--seeds" || a == "--none") && std::atoi(v.c_str()) <= 0) {
      std::fprintf(stderr, "lab_accuracy: %s must be a positive whole number, not '%s'\n", a.c_str(), v.c_str());
      return 2;
    }
  }
  const auto started = std::chrono::steady_clock::now();
  const auto run = [&](test::LabTruth truth, double size, unsigned seed) {
    const std::string folder = dir + "/" + test::name(truth) + "_" + std::to_string(size) + "_" + std::to_string(seed);
    std::filesystem::remove_all(folder);
    test::write_lab_dataset(seed, truth, size, folder);
    return analyze(read_dataset(folder), {}, {.specimen = false, .nested = false, .bootstrap_replicates = 0});
  };
  if (history) {
    history_table(
        [&](test::LabTruth truth, unsigned seed) {
          const std::string folder = dir + "/" + test::name(truth) + "_history_" + std::to_string(seed);
          std::filesystem::remove_all(folder);
          test::write_lab_dataset(seed, truth, 1.0, folder);
          return read_dataset(folder);
        },
        seeds, first_seed);
    std::fprintf(stderr, "[%6.0f s] done\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    return 0;
  }
  if (adequacy) {
    adequacy_table(run, seeds, first_seed);
    std::fprintf(stderr, "[%6.0f s] done\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    return 0;
  }
  std::printf("| truth | in the lab's forms | size | right | named instead (count) |\n|---|---|---|---|---|\n");
  const std::vector<test::LabTruth> truths = {test::LabTruth::exponential_stiffening,
                                              test::LabTruth::polynomial_stiffening,
                                              test::LabTruth::asymmetry,
                                              test::LabTruth::softening,
                                              test::LabTruth::recovering_softening,
                                              test::LabTruth::broadband,
                                              test::LabTruth::power_law,
                                              test::LabTruth::broadband_and_stiffening};
  for (test::LabTruth truth : truths)
    for (double size : {1.0, 0.3, 0.1}) {
      int ok = 0;
      std::map<std::string, int> instead;
      for (int s = 1; s <= seeds; ++s) {
        const Analysis a = run(truth, size, static_cast<unsigned>(s));
        if (test::names_expected_causes(truth, a.causes))
          ++ok;
        else
          ++instead[causes_of(a)];
      }
      std::string other;
      for (const auto& [k, v] : instead) other += (other.empty() ? "" : ", ") + k + " (" + std::to_string(v) + ")";
      std::printf("| %s | %s | %.1fx | %d of %d | %s |\n", test::name(truth), test::out_of_family(truth) ? "no" : "yes", size, ok, seeds,
                  other.c_str());
      std::fflush(stdout);
      std::fprintf(stderr, "[%6.0f s] %s at %.1fx done\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
                   test::name(truth), size);
    }
  int false_positives = 0;
  std::map<std::string, int> named;
  for (int s = 1; s <= nones; ++s) {
    const Analysis a = run(test::LabTruth::none, 1.0, static_cast<unsigned>(s));
    if (!a.causes.empty()) {
      ++false_positives;
      ++named[causes_of(a)];
    }
  }
  std::string other;
  for (const auto& [k, v] : named) other += (other.empty() ? "" : ", ") + k + " (" + std::to_string(v) + ")";
  std::printf("\nFalse positives on %d 'none' sets (linear Kelvin-Voigt truths): %d%s%s\n", nones, false_positives, other.empty() ? "" : ": ",
              other.c_str());
  std::fprintf(stderr, "[%6.0f s] done\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  return 0;
}
