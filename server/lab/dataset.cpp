#include "viscera/lab/dataset.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string_view>

#include <nlohmann/json.hpp>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/lab/csv_lines.hpp"
#include "viscera/lab/test_history.hpp"

namespace viscera::lab {

using common::InputError;
using common::JsonObject;

using common::InputError;
using common::JsonObject;
using nlohmann::json;

const char* to_string(Mode m) { return m == Mode::uniaxial ? "uniaxial" : "simple_shear"; }
const char* to_string(Control c) { return c == Control::strain ? "strain" : "stress"; }
const char* to_string(History h) { return h == History::carried ? "carried" : "reset"; }

namespace {

// A test more than this many times stiffer or softer than the others is in another unit.
constexpr double kUnitRatio = 250.0;
// Apparent moduli no tissue has: below 10 Pa (the softest brain and fat are about 100 Pa-1 kPa)
// and above 50 GPa (cortical bone is about 20 GPa).
constexpr double kSoftestPa = 10.0, kStiffestPa = 5e10;
// A test file larger than this is not a measurement of one specimen (1.3 million rows are 43 MB).
constexpr std::size_t kMaxCsvBytes = std::size_t{1} << 30;

TestData read_csv(const std::string& path, const std::string& file, Control control) {
  const std::string content = common::read_text_file(path, kMaxCsvBytes);
  CsvLines lines(content);
  const auto first = lines.next();
  if (!first) throw InputError(path, 1, "header", "file is empty");
  const auto header = csv_cells(*first);
  int col_t = -1, col_e = -1, col_s = -1, col_sd = -1;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] == "time_s")
      col_t = static_cast<int>(c);
    else if (header[c] == "strain")
      col_e = static_cast<int>(c);
    else if (header[c] == "stress_pa")
      col_s = static_cast<int>(c);
    else if (header[c] == "stress_sd_pa")
      col_sd = static_cast<int>(c);
  }
  for (const auto& [col, name] : {std::pair{col_t, "time_s"}, std::pair{col_e, "strain"}, std::pair{col_s, "stress_pa"}})
    if (col < 0)
      throw InputError(
          path, 1, name,
          "column missing (the first line, '" + common::printable(*first, 60) + "', must name the columns time_s,strain,stress_pa[,stress_sd_pa])");
  TestData t;
  t.file = file;
  t.control = control;
  long row = 1;
  while (const auto line = lines.next()) {
    ++row;
    if (line->empty() || *line == "\r") continue;
    const auto cells = csv_cells(*line);
    const auto value = [&](int col, const char* name) {
      if (col >= static_cast<int>(cells.size())) throw InputError(path, row, name, "missing value");
      std::string why;
      const auto v = common::read_number(cells[static_cast<std::size_t>(col)], &why);
      if (!v) throw InputError(path, row, name, why);
      return *v;
    };
    const double time = value(col_t, "time_s"), strain = value(col_e, "strain"), stress = value(col_s, "stress_pa");
    if (!t.time_s.empty() && !(time > t.time_s.back()))
      throw InputError(path, row, "time_s",
                       common::short_number(time) + " s does not increase (previous row " + common::short_number(t.time_s.back()) + " s)");
    if (std::abs(strain) > 5.0)
      throw InputError(path, row, "strain", common::short_number(strain) + " cannot be right: strain is dimensionless (1 = 100%), not percent");
    if (std::abs(stress) > 1e9)
      throw InputError(path, row, "stress_pa", common::short_number(stress) + " Pa cannot be right for soft tissue (stress in pascals?)");
    t.time_s.push_back(time);
    t.strain.push_back(strain);
    t.stress_pa.push_back(stress);
    if (col_sd >= 0) {
      const double sd = value(col_sd, "stress_sd_pa");
      if (sd < 0) throw InputError(path, row, "stress_sd_pa", common::short_number(sd) + " is negative");
      t.stress_sd_pa.push_back(sd);
    }
  }
  if (t.time_s.size() < 3) throw InputError(path, row, "", "fewer than 3 data rows");
  return t;
}

/// The test file named in dataset.json, which must lie inside the data-set folder (a data set is
/// a folder a user hands over; it must not make the tool read other files of the machine).
std::string test_path(const std::string& folder, const std::string& file, const JsonObject& test) {
  namespace fs = std::filesystem;
  const fs::path name(file);
  if (file.empty() || name.is_absolute()) test.fail("file", "'" + common::printable(file) + "' must be a file name relative to the data-set folder");
  const fs::path base = fs::weakly_canonical(fs::path(folder));
  const fs::path full = fs::weakly_canonical(base / name);
  const fs::path inside = full.lexically_relative(base);
  if (inside.empty() || *inside.begin() == "..")
    test.fail("file", "'" + common::printable(file) + "' lies outside the data-set folder " + common::printable(folder, 200));
  return full.string();
}

/// Stresses that cannot be in pascals: a test whose apparent modulus (peak |stress| / peak
/// |strain|) is hundreds of times the other tests' (one test in kPa or MPa), or a data set whose
/// apparent modulus is below any soft tissue or above bone.
void check_stress_units(const Dataset& d, const std::string& meta) {
  std::vector<double> modulus;
  for (const auto& t : d.tests) {
    double s = 0, e = 0;
    for (std::size_t k = 0; k < t.time_s.size(); ++k) {
      s = std::max(s, std::abs(t.stress_pa[k]));
      e = std::max(e, std::abs(t.strain[k]));
    }
    modulus.push_back(e > 0 ? s / e : 0.0);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  for (std::size_t k = 0; k < d.tests.size() && d.tests.size() >= 2; ++k) {
    std::vector<double> others = modulus;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
    const double m = median(others), ratio = modulus[k] / m;
    if (m > 0 && modulus[k] > 0 && (ratio > kUnitRatio || ratio < 1 / kUnitRatio))
      throw InputError((std::filesystem::path(d.folder) / d.tests[k].file).string(), 0, "stress_pa",
                       "apparent modulus " + common::short_number(modulus[k]) + " Pa is " + common::short_number(ratio) +
                           " times the other tests' (" + common::short_number(m) + " Pa): is this test in another unit (kPa, MPa)?");
  }
  const double m = median(modulus);
  if (m > 0 && m < kSoftestPa)
    throw InputError(meta, 0, "tests",
                     "apparent modulus " + common::short_number(m) + " Pa (peak stress / peak strain) is below any tissue (" +
                         common::short_number(kSoftestPa) + " Pa): are the stresses in kPa? The unit is Pa");
  if (m > kStiffestPa)
    throw InputError(meta, 0, "tests",
                     "apparent modulus " + common::short_number(m) + " Pa is above bone's (" + common::short_number(kStiffestPa) +
                         " Pa): are the stresses or strains in another unit?");
}

/// A stress-controlled test whose stress cannot be what it claims: over a long stretch (a fifth
/// of the test or more, five samples or more) the strain is held within its noise while the
/// stress, said to be commanded, moves (between the stretch's first and last quarter,
/// time-weighted) by an amount that at the test's apparent modulus should have moved the strain by
/// twenty times that noise. A held strain under a decaying stress is a relaxation test: its
/// "control" is the strain. (The converse is not refused: a stress that stays flat while the strain
/// moves is what a slack specimen, or Fung's exponential in compression, does under strain
/// control.)
void check_control(const TestData& t, const JsonObject& entry) {
  if (t.control != Control::stress) return;
  const std::vector<double>& stress = t.stress_pa;
  const std::vector<double>& strain = t.strain;
  const std::size_t n = t.time_s.size();
  double peak_stress = 0, peak_strain = 0, lo = strain[0], hi = strain[0];
  for (std::size_t k = 0; k < n; ++k) {
    peak_stress = std::max(peak_stress, std::abs(stress[k]));
    peak_strain = std::max(peak_strain, std::abs(strain[k]));
    lo = std::min(lo, strain[k]);
    hi = std::max(hi, strain[k]);
  }
  if (peak_stress <= 0 || peak_strain <= 0) return;
  const double compliance = peak_strain / peak_stress;  // strain per pascal, at the apparent modulus
  const double tol = 4 * noise_from_second_differences(strain) + 1e-9 * (hi - lo);
  const double duration = t.time_s.back() - t.time_s.front();
  // Time-weighted mean of the stress over [a, b] (each sample holds until the next).
  const auto mean = [&](double a, double b) {
    double sum = 0, w = 0;
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const double from = std::max(a, t.time_s[k]), to = std::min(b, t.time_s[k + 1]);
      if (to > from) {
        sum += stress[k] * (to - from);
        w += to - from;
      }
    }
    return w > 0 ? sum / w : 0.0;
  };
  std::size_t start = 0;
  for (std::size_t k = 1; k <= n; ++k) {
    if (k < n && std::abs(strain[k] - strain[start]) <= tol) continue;
    const std::size_t end = k - 1;  // strain held over [start, end]
    const double t0 = t.time_s[start], t1 = t.time_s[end], quarter = (t1 - t0) / 4;
    if (end >= start + 4 && t1 - t0 >= 0.2 * duration) {
      const double moved = std::abs(mean(t1 - quarter, t1) - mean(t0, t0 + quarter));
      if (moved * compliance > 20 * tol)
        entry.fail("control", "'stress' claimed for " + t.file + ", but its strain is held from " + common::short_number(t0) + " to " +
                                  common::short_number(t1) + " s while its stress moves by " + common::short_number(moved) +
                                  " Pa: that is a relaxation (strain-controlled) test; is \"control\" \"strain\"?");
    }
    start = k;
  }
}

/// A specimen object; with `defaults` (a test's own), each field absent takes the data set's.
Specimen read_specimen(const JsonObject& s, const Specimen* defaults) {
  s.require_known({"length_m", "width_m", "thickness_m", "density_kg_m3"});
  if (!defaults)
    return {s.number("length_m", 1e-6, 10), s.number("width_m", 1e-6, 10), s.number("thickness_m", 1e-6, 10), s.number("density_kg_m3", 1, 1e5)};
  return {s.number("length_m", 1e-6, 10, defaults->length_m), s.number("width_m", 1e-6, 10, defaults->width_m),
          s.number("thickness_m", 1e-6, 10, defaults->thickness_m), s.number("density_kg_m3", 1, 1e5, defaults->density_kg_m3)};
}

}  // namespace

double noise_from_second_differences(const std::vector<double>& v) {
  std::vector<double> d2;
  for (std::size_t k = 2; k < v.size(); ++k) d2.push_back(std::abs(v[k] - 2 * v[k - 1] + v[k - 2]));
  if (d2.empty()) return 0.0;
  std::nth_element(d2.begin(), d2.begin() + static_cast<long>(d2.size() / 2), d2.end());
  return d2[d2.size() / 2] / 0.6745 / std::sqrt(6.0);
}

double quantum_of(const std::vector<double>& v) {
  double quantum = 0;
  for (std::size_t k = 1; k < v.size(); ++k)
    if (const double step = std::abs(v[k] - v[k - 1]); step > 0 && (quantum == 0 || step < quantum)) quantum = step;
  return quantum;
}

double noise_of_reading(const std::vector<double>& v) {
  if (const double n = noise_from_second_differences(v); n > 0 || v.size() < 3) return n;
  // More than half the second differences are exactly zero: a reading quantised more coarsely
  // than its noise, and their median says nothing. Their RMS over the central 98% then (the
  // largest 2%, the command's corners, left out), never below the quantum's own noise.
  std::vector<double> d2;
  for (std::size_t k = 2; k < v.size(); ++k) d2.push_back(std::abs(v[k] - 2 * v[k - 1] + v[k - 2]));
  std::sort(d2.begin(), d2.end());
  const std::size_t kept = std::max<std::size_t>(1, d2.size() * 98 / 100);
  double sq = 0;
  for (std::size_t k = 0; k < kept; ++k) sq += d2[k] * d2[k];
  return std::max(std::sqrt(sq / static_cast<double>(kept) / 6.0), quantum_of(v) / std::sqrt(12.0));
}

Dataset read_dataset(const std::string& folder) {
  const std::string meta = (std::filesystem::path(folder) / "dataset.json").string();
  if (!std::filesystem::exists(meta)) throw InputError(meta, 0, "", "cannot open file (is " + folder + " a data set folder?)");
  const json j = common::read_json_file(meta);
  const JsonObject top(j, meta);
  top.require_known({"name", "mode", "contact", "history", "specimen", "tests", "max_test_duration_s", "import"});
  Dataset d;
  d.folder = folder;
  d.name = top.text("name", std::filesystem::path(folder).filename().string());
  d.import_note = top.text("import", "");
  d.mode = top.choice("mode", {"uniaxial", "simple_shear"}, "") == "uniaxial" ? Mode::uniaxial : Mode::simple_shear;
  d.platens = top.choice("contact", {"bonded", "platens"}, "bonded") == "platens";
  if (d.platens && d.mode != Mode::uniaxial) top.fail("contact", "\"platens\" needs \"mode\": \"uniaxial\" (platens compress; they do not shear)");
  d.history = top.choice("history", {"carried", "reset"}, "carried") == "carried" ? History::carried : History::reset;
  d.specimen = read_specimen(top.object("specimen"), nullptr);
  // Longer tests exist (creep over days) but are rare; a span beyond a day is more often a time
  // column in another unit, so it must be declared.
  const double max_duration_s = top.number("max_test_duration_s", 1e-3, 1e9, 86400.0);
  const json& tests = top.array("tests", 1);
  for (std::size_t k = 0; k < tests.size(); ++k) {
    const JsonObject t(tests[k], meta, "tests[" + std::to_string(k) + "]");
    t.require_known({"file", "control", "specimen"});
    const std::string file = t.text("file");
    const Control control = t.choice("control", {"strain", "stress"}, "") == "strain" ? Control::strain : Control::stress;
    d.tests.push_back(read_csv(test_path(folder, file, t), file, control));
    if (t.has("specimen")) d.tests.back().specimen = read_specimen(t.object("specimen"), &d.specimen);
    const TestData& added = d.tests.back();
    check_control(added, t);
    const double span = added.time_s.back() - added.time_s.front();
    if (span > max_duration_s)
      throw InputError((std::filesystem::path(folder) / file).string(), 0, "time_s",
                       "the test spans " + common::short_number(span) + " s, more than " + common::short_number(max_duration_s) +
                           " s: is the time in another unit? (a longer test is declared with \"max_test_duration_s\" in dataset.json)");
  }
  check_stress_units(d, meta);
  if (d.platens)
    for (const auto& t : d.tests) {
      // Platens compress: a stretch larger than the strain column's own scatter is a sign flipped.
      double largest = 0.0;
      for (const double e : t.strain) largest = std::max(largest, std::abs(e));
      for (std::size_t k = 0; k < t.strain.size(); ++k)
        if (t.strain[k] > 0.01 * largest)
          throw InputError((std::filesystem::path(folder) / t.file).string(), static_cast<long>(k + 2), "strain",
                           common::short_number(t.strain[k]) +
                               " is a stretch, but \"contact\": \"platens\" compresses (compression is negative strain and stress; "
                               "viscera-lab import --compression-positive negates exports that count it positive)");
    }
  carry_history(d);
  return d;
}

void write_dataset(const Dataset& d, const std::string& folder) {
  common::create_output_folder(folder, "folder");
  json j;
  j["name"] = d.name;
  j["mode"] = to_string(d.mode);
  if (d.platens) j["contact"] = "platens";
  j["history"] = to_string(d.history);
  if (!d.import_note.empty()) j["import"] = d.import_note;
  const auto specimen = [](const Specimen& sp) {
    return json{{"length_m", sp.length_m}, {"width_m", sp.width_m}, {"thickness_m", sp.thickness_m}, {"density_kg_m3", sp.density_kg_m3}};
  };
  j["specimen"] = specimen(d.specimen);
  j["tests"] = json::array();
  for (const auto& t : d.tests) {
    j["tests"].push_back({{"file", t.file}, {"control", to_string(t.control)}});
    if (t.specimen) j["tests"].back()["specimen"] = specimen(*t.specimen);
    std::ostringstream csv;
    csv.precision(10);
    csv << "time_s,strain,stress_pa" << (t.stress_sd_pa.empty() ? "" : ",stress_sd_pa") << "\n";
    for (std::size_t k = 0; k < t.time_s.size(); ++k) {
      csv << t.time_s[k] << ',' << t.strain[k] << ',' << t.stress_pa[k];
      if (!t.stress_sd_pa.empty()) csv << ',' << t.stress_sd_pa[k];
      csv << '\n';
    }
    common::write_file_text((std::filesystem::path(folder) / t.file).string(), csv.str());
  }
  common::write_file_text((std::filesystem::path(folder) / "dataset.json").string(), j.dump(2) + "\n");
}

}  // namespace viscera::lab
