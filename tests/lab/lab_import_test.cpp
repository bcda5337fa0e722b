// viscera-lab import: a test machine's exports become a data set by the stated conversion  // SPDX-License-Identifier: Apache-2.0
// (strain from displacement over the gauge length, stress from force over the area), in each
// machine's units and column names, with every check a data set gets.
#include "viscera/lab/lab_import.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/lab/analysis.hpp"

using namespace viscera::lab;

TEST(Import, ExportsBecomeADataSetByTheStatedConversion) {
  const std::string dir = std::string(VISCERA_TEST_TMP) + "/import";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir + "/sample A.txt");
    f << "\xEF\xBB\xBF"
      << "\"Time\"\t\"Force\"\t\"Disp\"\r\n";
    for (int k = 0; k <= 100; ++k) f << 0.1 * k << '\t' << 2.0 * std::min(k, 50) << '\t' << 0.02 * std::min(k, 50) << "\r\n";
  }
  ImportOptions o;
  o.specimen = {0.01, 0.003, 0.002, 1050};
  o.time = parse_import_column("time", "Time", ImportQuantity::time);
  o.force = parse_import_column("force", "Force:mN", ImportQuantity::force);
  o.displacement = parse_import_column("displacement", "Disp:mm", ImportQuantity::displacement);
  const Dataset d = import_dataset({dir + "/sample A.txt"}, o, dir + "/ds");
  ASSERT_EQ(d.tests.size(), 1u);
  const TestData& t = d.tests[0];
  EXPECT_EQ(t.file, "sample A.csv");
  ASSERT_EQ(t.time_s.size(), 101u);
  // At row 30: 60 mN over 3 mm x 2 mm = 10 kPa; 0.6 mm over 10 mm = 0.06.
  EXPECT_NEAR(t.time_s[30], 3.0, 1e-12);
  EXPECT_NEAR(t.stress_pa[30], 60e-3 / 6e-6, 1e-6);
  EXPECT_NEAR(t.strain[30], 0.06, 1e-12);
  EXPECT_NE(d.import_note.find("'Force' [mN]"), std::string::npos) << d.import_note;
  const auto error = [&](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Not over an existing data set; a column that is not there, named with the ones that are.
  EXPECT_NE(error([&] { import_dataset({dir + "/sample A.txt"}, o, dir + "/ds"); }).find("already exists"), std::string::npos);
  ImportOptions wrong = o;
  wrong.force.name = "Load";
  const std::string missing = error([&] { import_dataset({dir + "/sample A.txt"}, wrong, dir + "/ds2"); });
  EXPECT_NE(missing.find("sample A.txt:1: Load: no such column (--force); the columns are: Time, Force, Disp"), std::string::npos) << missing;
  // Line ends of CR alone (some machines' exports) end lines as CR LF does: the same test.
  {
    std::ifstream in(dir + "/sample A.txt");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.erase(std::remove(text.begin(), text.end(), '\n'), text.end());
    std::ofstream(dir + "/sample C.txt") << text;
  }
  const Dataset cr = import_dataset({dir + "/sample C.txt"}, o, dir + "/ds-cr");
  ASSERT_EQ(cr.tests.size(), 1u);
  EXPECT_EQ(cr.tests[0].time_s, t.time_s);
  EXPECT_EQ(cr.tests[0].stress_pa, t.stress_pa);
  // A header of thousands of cells: the error names a dozen of them, not the whole file.
  {
    std::ofstream f(dir + "/wide.txt");
    for (int k = 0; k < 5000; ++k) f << (k ? "\t" : "") << "column number " << k;
    f << "\n1\n";
  }
  const std::string wide = error([&] { import_dataset({dir + "/wide.txt"}, o, dir + "/ds-wide"); });
  EXPECT_NE(wide.find("no such column (--time)"), std::string::npos) << wide.substr(0, 300);
  EXPECT_NE(wide.find("and 4988 more"), std::string::npos) << wide.substr(0, 300);
  EXPECT_LT(wide.size(), 700u);
  // A column taken by name that the header names twice: which one is meant cannot be told.
  {
    std::ofstream f(dir + "/twice.txt");
    f << "Time\tForce\tDisp\tForce\n0\t0\t0\t0\n";
  }
  EXPECT_NE(error([&] { import_dataset({dir + "/twice.txt"}, o, dir + "/ds-twice"); }).find("twice.txt:1: Force: named twice in the header"),
            std::string::npos);
  // Millimetres declared as metres: strains of 1000% are refused by the data set's own checks.
  wrong = o;
  wrong.displacement = parse_import_column("displacement", "Disp:m", ImportQuantity::displacement);
  const std::string percent = error([&] { import_dataset({dir + "/sample A.txt"}, wrong, dir + "/ds3"); });
  EXPECT_NE(percent.find("strain"), std::string::npos) << percent;
  EXPECT_NE(percent.find("cannot be right"), std::string::npos) << percent;
  EXPECT_NE(error([] { parse_import_column("force", "Force:lb", ImportQuantity::force); }).find("--force: unit 'lb' is not a force unit"),
            std::string::npos);
}

// A machine's exports that start under a preload, with its displacement zero elsewhere (the pig
// discs' "force below the starting one" and their preload at t = 0): imported with --tare and
// --zero-displacement they are the same data set as the tests without them (the analysis on the
// generator's own data, another path), and without the tare the preload is a stress the
// tissue's law cannot give at zero strain.
