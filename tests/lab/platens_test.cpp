// The lab between platens (issue 38): a specimen compressed between plates it is not bonded to.  // SPDX-License-Identifier: Apache-2.0
// The platens close a gap before they load it (a toe) and cannot pull (contact is lost where the
// tissue recovers slower than they retreat). The data come from a generator of their own, built on
// neither of the lab's forms: a rough face whose gaps spread over a range, columns that recover
// freely at zero stress. A machine's exports of such discs, with a table of their sizes, are
// imported as a researcher would.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/common/command_line.hpp"
#include "viscera/lab/analysis.hpp"
#include "viscera/lab/lab_import.hpp"
#include "viscera/lab/material_export.hpp"

using namespace viscera::lab;

namespace {

/// Discs with a rough face, compressed between platens they are not bonded to. Three discs (4.4,
/// 3.8 and 4.1 mm thick, 10 mm across), five steps of 10% to 50% at 1 um/s held 400 s, then the
/// platen goes back to zero at 20 um/s and waits 300 s; 0.5 Hz, 200 Pa of noise, forces quantised at
/// 0.02 N (255 Pa). The face: 24 columns of equal area whose gaps to the platen spread evenly over
/// [0, 2 gap] (a smooth toe, not one gap). Each column: an exponential stiffening in compression
/// (E = 15 kPa, B = 4) beside one Maxwell arm (40 kPa, 300 s), pushed but never pulled: a column
/// that the retreating platen would have to pull recovers freely at zero stress until the platen
/// catches up (loss of contact). `platens` false: the same data declared bonded.
Dataset rough_discs(double gap, bool platens) {
  std::mt19937 rng(11);
  std::normal_distribution<double> gauss(0.0, 200.0);
  Dataset d;
  d.name = "rough-discs";
  d.folder = "generated";
  d.mode = Mode::uniaxial;
  d.platens = platens;
  const double area = 3.14159265358979 * 0.005 * 0.005, quantum = 0.02 / area, tau = 300.0, E = 15e3, B = 4.0, E1 = 40e3, dt = 2.0;
  const double decay = std::exp(-dt / tau), gain = E1 * tau / dt * (1 - decay);
  d.specimen = {4.4e-3, 0.00886, 0.00886, 1050};
  constexpr int kColumns = 24;
  const auto stress = [&](double strain, double strain_before, double q_before) {
    return -(E / B) * std::expm1(-B * strain) + q_before * decay + gain * (strain - strain_before);
  };
  int k = 0;
  for (const double thickness : {4.4e-3, 3.8e-3, 4.1e-3}) {
    TestData t;
    t.file = "disc" + std::to_string(++k) + ".csv";
    if (k > 1) t.specimen = Specimen{thickness, 0.00886, 0.00886, 1050};
    // The platen's strain at each second: ramps and holds, then back to zero.
    std::vector<double> platen;
    const double rate = 1e-6 / thickness;
    for (int step = 0; step < 5; ++step)
      for (double s = 0; s < 0.1 / rate + 400.0; s += dt) platen.push_back(-(0.1 * step + std::min(0.1, rate * s)));
    for (double e = platen.back(); e < 0; e += 20 * rate * dt) platen.push_back(e);
    for (double s = 0; s < 300; s += dt) platen.push_back(0.0);
    std::array<double, kColumns> strain{}, q{};
    for (std::size_t j = 0; j < platen.size(); ++j) {
      double total = 0.0;
      for (int c = 0; c < kColumns; ++c) {
        const double g = 2 * gap * (c + 0.5) / kColumns;
        double next = std::min(0.0, platen[j] + g);  // in contact: the platen sets the column's strain
        if (stress(next, strain[c], q[c]) > 0) {
          // The platen would pull: the column recovers on its own, at zero stress (bisection; the
          // stress grows with the strain), more compressed than the platen holds it.
          double lo = -1.0, hi = next;
          for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            (stress(mid, strain[c], q[c]) > 0 ? hi : lo) = mid;
          }
          next = 0.5 * (lo + hi);
        }
        const double s = stress(next, strain[c], q[c]);
        q[c] = q[c] * decay + gain * (next - strain[c]);
        strain[c] = next;
        total += s / kColumns;
      }
      t.time_s.push_back(static_cast<double>(j) * dt);
      t.strain.push_back(platen[j]);
      t.stress_pa.push_back(quantum * std::round((total + gauss(rng)) / quantum));
    }
    d.tests.push_back(std::move(t));
  }
  return d;
}

}  // namespace

// A toe the data show (a 5% mean gap, up to 10% on the roughest part of the face, about 2 kPa of
// stress the bonded model puts where the data have little) and a retreat faster than the tissue
// recovers: declared as platens, the lab names the contact it takes up as a cause of the test,
// confirmed on discs it never saw, keeps it out of the material for the organ, and predicts better
// than the same lab told the discs were bonded. Flat discs (no gap) under the same protocol: no
// contact to take up is named.
TEST(Platens, RoughDiscsTakeUpContactAndLoseIt) {
  const double gap = 0.05;
  const AnalyzeOptions fast{.specimen = false, .max_fit_points = 800, .bootstrap_replicates = 0};
  const auto t0 = std::chrono::steady_clock::now();
  const Dataset d = rough_discs(gap, true);
  const Analysis a = analyze(d, {}, fast);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Analysis bonded = analyze(rough_discs(gap, false), {}, fast);
  const Analysis flat = analyze(rough_discs(0.0, true), {}, fast);
  const MaterialModel& m = a.supported_model();
  std::printf("[ figure ] rough discs, platens: %s\n", a.verdict.c_str());
  std::printf(
      "[ figure ] rough discs: platens: baseline held-out %.0f Pa, final %.0f Pa (%s, gap %.4f), nested %.0f Pa (gain %.2f), noise %.0f Pa / "
      "holds %.0f Pa, %.1f s; declared bonded: final %.0f Pa (%s), nested %.0f Pa; flat discs: %s\n",
      a.baseline.heldout_rms_pa, a.final.heldout_rms_pa, m.describe().c_str(), m.contact_strain, a.nested_heldout_rms_pa, a.nested_gain, a.noise_pa,
      a.noise_check.holds_pa, seconds, bonded.final.heldout_rms_pa, bonded.supported_model().describe().c_str(), bonded.nested_heldout_rms_pa,
      flat.supported_model().describe().c_str());
  const auto named = a.named_causes();
  const auto has = [](const std::vector<Mechanism>& v, Mechanism x) { return std::find(v.begin(), v.end(), x) != v.end(); };
  EXPECT_EQ(a.causes_status, CausesStatus::confirmed) << a.verdict;
  EXPECT_TRUE(has(named, Mechanism::contact_take_up)) << a.verdict;
  EXPECT_TRUE(has(named, Mechanism::strain_stiffening)) << a.verdict;
  EXPECT_FALSE(has(named, Mechanism::first_load_softening)) << a.verdict;
  EXPECT_NE(a.verdict.find("contact_take_up"), std::string::npos);
  // The one gap the lab fits stands for a spread of gaps from 0 to twice the mean: inside it, away from its ends.
  EXPECT_GT(m.contact_strain, 0.2 * gap);
  EXPECT_LT(m.contact_strain, 2.0 * gap);
  // Told the truth about the fixture, the lab predicts discs it never saw better than told they were bonded.
  EXPECT_LT(a.nested_heldout_rms_pa, 0.8 * bonded.nested_heldout_rms_pa);
  // No gap, no contact to take up (the platens' loss of contact on the retreat is still there).
  EXPECT_FALSE(has(flat.named_causes(), Mechanism::contact_take_up)) << flat.verdict;
  // Between platens no prediction pulls.
  for (const auto& t : d.tests)
    for (const double s : predict_stress(m, t)) EXPECT_LE(s, 0.0);
  // The material for the organ is the tissue's: the gap stays with the test, and the note says so
  // (in a form the GPS has: Ogden's, which the fit may choose, is not handed over).
  MaterialModel handed = m;
  handed.stiffening_form = StiffeningForm::odd_exponential;
  std::string why, note;
  const std::string material = material_file_text(handed, d, "rough discs", &why, &note);
  ASSERT_FALSE(material.empty()) << why;
  EXPECT_NE(note.find("belongs to the test"), std::string::npos) << note;
  EXPECT_EQ(material.find("contact"), std::string::npos) << material;
}

// A machine's exports of the three rough discs as it writes them (compression positive, N and mm,
// one file per disc) and the lab's table of their thicknesses: imported between platens, each test
// is converted with its own specimen's height and area and keeps it, and the data are the
// generator's to the files' precision, so the analysis above is what a researcher gets from the
// exports without editing a number.
TEST(Platens, SeveralSpecimensImportedFromATable) {
  const Dataset direct = rough_discs(0.05, true);
  const std::string dir = std::string(VISCERA_TEST_TMP) + "/import_discs";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::vector<std::string> files;
  std::ofstream table(dir + "/specimens.csv");
  table << "file,length_m\n";
  for (const TestData& t : direct.tests) {
    const Specimen& sp = specimen_of(direct, t);
    files.push_back(dir + "/" + t.file.substr(0, t.file.size() - 4) + ".txt");
    table << t.file.substr(0, t.file.size() - 4) << ".txt," << sp.length_m << "\n";
    std::ofstream f(files.back());
    f.precision(12);
    f << "Time [s]\tForce [N]\tPosition [mm]\n";
    for (std::size_t i = 0; i < t.time_s.size(); ++i)
      f << t.time_s[i] << '\t' << -t.stress_pa[i] * sp.width_m * sp.thickness_m << '\t' << -1e3 * t.strain[i] * sp.length_m << '\n';
  }
  table.close();
  ImportOptions o;
  o.specimen = direct.specimen;
  o.time = parse_import_column("time", "Time [s]", ImportQuantity::time);
  o.force = parse_import_column("force", "Force [N]:N", ImportQuantity::force);
  o.displacement = parse_import_column("displacement", "Position [mm]:mm", ImportQuantity::displacement);
  o.platens = o.compression_positive = true;
  o.specimen_of = read_specimen_table(dir + "/specimens.csv", o.specimen);
  const Dataset d = import_dataset(files, o, dir + "/discs");
  EXPECT_TRUE(d.platens);
  ASSERT_EQ(d.tests.size(), direct.tests.size());
  for (std::size_t k = 0; k < d.tests.size(); ++k) {
    const Specimen& want = specimen_of(direct, direct.tests[k]);
    ASSERT_TRUE(d.tests[k].specimen.has_value()) << k;
    EXPECT_DOUBLE_EQ(d.tests[k].specimen->length_m, want.length_m) << k;
    for (std::size_t i = 0; i < d.tests[k].time_s.size(); i += 53) {
      EXPECT_NEAR(d.tests[k].strain[i], direct.tests[k].strain[i], 1e-10) << k << " row " << i;
      // dataset.json's CSVs carry 10 significant digits.
      EXPECT_NEAR(d.tests[k].stress_pa[i], direct.tests[k].stress_pa[i], 1e-9 * std::abs(direct.tests[k].stress_pa[i]) + 1e-9) << k << " row " << i;
    }
  }
  // A table with a row for a file that is not an export given is refused, naming it.
  std::ofstream(dir + "/extra.csv") << "file,length_m\ndisc9.txt,0.004\n";
  o.specimen_of = read_specimen_table(dir + "/extra.csv", o.specimen);
  try {
    import_dataset(files, o, dir + "/extra");
    FAIL() << "a table naming no export was taken";
  } catch (const viscera::common::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("disc9.txt"), std::string::npos) << e.what();
  }
}
