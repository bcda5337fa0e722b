#include "viscera/lab/lab_import.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>
#include <string_view>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/lab/csv_lines.hpp"

namespace viscera::lab {

using common::InputError;

namespace {

// An export larger than this is not one test (a 1 kHz logger over a day is about 100 MB).
constexpr std::size_t kMaxExportBytes = std::size_t{1} << 30;

const char* quantity_name(ImportQuantity q) {
  switch (q) {
    case ImportQuantity::time: return "time";
    case ImportQuantity::force: return "force";
    case ImportQuantity::displacement: return "displacement";
  }
  return "?";
}

// The header row of a table a machine or a lab wrote, and its separator: comma, semicolon or tab,
// whichever the header holds most of.
std::vector<std::string> read_header(CsvLines& lines, const std::string& path, char* separator) {
  const auto first = lines.next();
  if (!first) throw InputError(path, 1, "header", "file is empty");
  for (const char c : {';', '\t'})
    if (std::count(first->begin(), first->end(), c) > std::count(first->begin(), first->end(), *separator)) *separator = c;
  return csv_cells(*first, *separator);
}

// A cell beyond the header's columns belongs to no column: a separator inside a value (a decimal
// comma in a comma-separated file), or a column left unnamed. Empty ones (a spreadsheet's trailing
// separators) say nothing.
void refuse_cells_beyond(const std::vector<std::string>& cells, std::size_t columns, const std::string& path, long row) {
  for (std::size_t c = columns; c < cells.size(); ++c)
    if (!cells[c].empty() && cells[c] != "\r")
      throw InputError(path, row, "cell " + std::to_string(c + 1),
                       "'" + common::printable(cells[c], 30) + "' lies beyond the header's " + std::to_string(columns) +
                           " columns (a separator inside a value, or a column without a name)");
}

}  // namespace

ImportColumn parse_import_column(const std::string& flag, const std::string& text, ImportQuantity q) {
  static const std::vector<std::pair<std::string, double>> time{{"s", 1.0}, {"ms", 1e-3}, {"min", 60.0}, {"h", 3600.0}},
      force{{"N", 1.0}, {"mN", 1e-3}, {"kN", 1e3}}, displacement{{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}};
  const auto& units = q == ImportQuantity::time ? time : q == ImportQuantity::force ? force : displacement;
  ImportColumn c;
  const std::size_t colon = text.rfind(':');
  c.name = text.substr(0, colon);
  c.unit = colon == std::string::npos ? units.front().first : text.substr(colon + 1);
  if (c.name.empty()) throw common::UsageError("--" + flag + ": '" + text + "' names no column (COLUMN or COLUMN:UNIT)");
  for (const auto& [unit, factor] : units)
    if (unit == c.unit) {
      c.to_si = factor;
      return c;
    }
  std::string known;
  for (const auto& [unit, factor] : units) known += (known.empty() ? "" : ", ") + unit;
  throw common::UsageError("--" + flag + ": unit '" + c.unit + "' is not a " + quantity_name(q) + " unit (" + known + ")");
}

std::map<std::string, Specimen> read_specimen_table(const std::string& path, const Specimen& defaults) {
  const std::string content = common::read_text_file(path, std::size_t{1} << 24);
  CsvLines lines(content);
  char separator = ',';
  auto header = read_header(lines, path, &separator);
  while (!header.empty() && (header.back().empty() || header.back() == "\r")) header.pop_back();  // a spreadsheet's trailing separators
  static const std::vector<std::string> known{"file", "length_m", "width_m", "thickness_m", "density_kg_m3"};
  for (std::size_t c = 0; c < header.size(); ++c)
    if (header[c].empty()) throw InputError(path, 1, "column " + std::to_string(c + 1), "has no name");
  for (const auto& h : header)
    if (std::find(known.begin(), known.end(), h) == known.end())
      throw InputError(path, 1, common::printable(h, 30), "unknown column (file, length_m, width_m, thickness_m, density_kg_m3)");
  for (std::size_t c = 1; c < header.size(); ++c)
    if (std::find(header.begin(), header.begin() + static_cast<long>(c), header[c]) != header.begin() + static_cast<long>(c))
      throw InputError(path, 1, header[c], "named twice in the header");
  if (std::find(header.begin(), header.end(), "file") == header.end()) throw InputError(path, 1, "file", "no such column: each row names an export");
  std::map<std::string, Specimen> table;
  long row = 1;
  while (const auto line = lines.next()) {
    ++row;
    if (line->empty() || *line == "\r") continue;
    const auto cells = csv_cells(*line, separator);
    refuse_cells_beyond(cells, header.size(), path, row);
    std::string file;
    Specimen sp = defaults;
    for (std::size_t c = 0; c < header.size(); ++c) {
      const std::string cell = c < cells.size() ? cells[c] : "";
      if (header[c] == "file") {
        file = cell;
        continue;
      }
      if (cell.empty()) continue;  // the data set's value
      std::string why;
      const auto v = common::read_number(cell, &why);
      if (!v) throw InputError(path, row, header[c], why);
      const double hi = header[c] == "density_kg_m3" ? 1e5 : 10.0;
      if (!(*v > 0 && *v <= hi))
        throw InputError(path, row, header[c], common::short_number(*v) + " is outside (0, " + common::short_number(hi) + "]");
      (header[c] == "length_m"      ? sp.length_m
       : header[c] == "width_m"     ? sp.width_m
       : header[c] == "thickness_m" ? sp.thickness_m
                                    : sp.density_kg_m3) = *v;
    }
    if (file.empty()) throw InputError(path, row, "file", "empty: each row names an export");
    if (!table.emplace(file, sp).second) throw InputError(path, row, "file", "'" + common::printable(file, 60) + "' is named twice");
  }
  return table;
}

TestData import_test(const std::string& path, const ImportOptions& o, ImportOffsets* taken_off) {
  const std::string content = common::read_text_file(path, kMaxExportBytes);
  CsvLines lines(content);
  char separator = ',';
  const auto header = read_header(lines, path, &separator);
  const auto column = [&](const ImportColumn& c, const char* flag) {
    const auto at = std::find(header.begin(), header.end(), c.name);
    if (at == header.end()) {
      // At most 12 names, each cut: a header of thousands of cells (a file whose line ends were
      // not seen) made an error line of megabytes.
      std::string names;
      for (std::size_t k = 0; k < std::min<std::size_t>(header.size(), 12); ++k)
        names += (names.empty() ? "" : ", ") + common::printable(header[k], 30);
      if (header.size() > 12) names += ", and " + std::to_string(header.size() - 12) + " more";
      throw InputError(path, 1, common::printable(c.name, 40), std::string("no such column (--") + flag + "); the columns are: " + names);
    }
    if (std::find(at + 1, header.end(), c.name) != header.end())
      throw InputError(path, 1, common::printable(c.name, 40), std::string("named twice in the header (--") + flag + " cannot tell which)");
    return static_cast<std::size_t>(at - header.begin());
  };
  const std::size_t ct = column(o.time, "time"), cf = column(o.force, "force"), cd = column(o.displacement, "displacement");
  const bool shear = o.mode == Mode::simple_shear;
  const auto own = o.specimen_of.find(std::filesystem::path(path).filename().string());
  const Specimen& sp = own == o.specimen_of.end() ? o.specimen : own->second;
  const double gauge = shear ? sp.thickness_m : sp.length_m, area = shear ? sp.length_m * sp.width_m : sp.width_m * sp.thickness_m;
  TestData t;
  t.file = std::filesystem::path(path).stem().string() + ".csv";
  t.control = o.control;
  long row = 1;
  while (const auto line = lines.next()) {
    ++row;
    if (line->empty() || *line == "\r") continue;
    const auto cells = csv_cells(*line, separator);
    refuse_cells_beyond(cells, header.size(), path, row);
    const auto value = [&](std::size_t col, const ImportColumn& c) {
      if (col >= cells.size()) throw InputError(path, row, c.name, "missing value");
      std::string why;
      const auto v = common::read_number(cells[col], &why);
      if (!v) throw InputError(path, row, c.name, why);
      return *v * c.to_si;
    };
    const double sign = o.compression_positive ? -1.0 : 1.0;
    t.time_s.push_back(value(ct, o.time));
    t.strain.push_back(sign * value(cd, o.displacement) / gauge + 0.0);  // + 0: no -0 from a negated 0
    t.stress_pa.push_back(sign * value(cf, o.force) / area + 0.0);
  }
  if (t.time_s.size() < 3) throw InputError(path, row, "rows", std::to_string(t.time_s.size()) + " rows of data: a test needs at least 3");
  ImportOffsets off;
  if (o.tare) {
    // The force at rest: the mean over the leading rows whose displacement is the first row's
    // (the machine holding the specimen before it moves it), at least the first row.
    std::size_t rest = 1;
    while (rest < t.strain.size() && t.strain[rest] == t.strain.front()) ++rest;
    double rest_stress = 0.0;
    for (std::size_t i = 0; i < rest; ++i) rest_stress += t.stress_pa[i] / static_cast<double>(rest);
    off.force_n = rest_stress * area;
    for (double& s : t.stress_pa) s -= rest_stress;
  }
  if (o.zero_displacement) {
    off.displacement_m = t.strain.front() * gauge;
    const double first_strain = t.strain.front();
    for (double& e : t.strain) e -= first_strain;
  }
  if (o.platens) {
    // Checked here, before anything is written, as read_dataset checks it, but naming the export's row.
    double largest = 0.0;
    for (const double e : t.strain) largest = std::max(largest, std::abs(e));
    for (std::size_t k = 0; k < t.strain.size(); ++k)
      if (t.strain[k] > 0.01 * largest)
        throw InputError(path, static_cast<long>(k + 2), o.displacement.name,
                         common::short_number(t.strain[k] * gauge) +
                             " m is a stretch, but --platens compresses (--compression-positive negates exports that count compression positive)");
  }
  if (taken_off) *taken_off = off;
  return t;
}

Dataset import_dataset(const std::vector<std::string>& files, const ImportOptions& o, const std::string& folder) {
  const std::string meta = (std::filesystem::path(folder) / "dataset.json").string();
  if (std::filesystem::exists(meta)) throw InputError(meta, 0, "", "already exists: import writes a new data set, never over one");
  Dataset d;
  d.name = o.name.empty() ? std::filesystem::path(folder).filename().string() : o.name;
  d.mode = o.mode;
  d.platens = o.platens;
  d.history = o.history;
  d.specimen = o.specimen;
  std::set<std::string> names;
  std::string offsets;
  for (const auto& named : o.specimen_of)
    if (const std::string& name = named.first;
        std::none_of(files.begin(), files.end(), [&](const std::string& f) { return std::filesystem::path(f).filename().string() == name; }))
      throw common::UsageError("--specimens: the table names '" + common::printable(name, 60) + "', which is not one of the exports given");
  for (const auto& f : files) {
    ImportOffsets off;
    d.tests.push_back(import_test(f, o, &off));
    if (const auto own = o.specimen_of.find(std::filesystem::path(f).filename().string()); own != o.specimen_of.end())
      d.tests.back().specimen = own->second;
    if (o.tare || o.zero_displacement)
      offsets += (offsets.empty() ? "" : ", ") + d.tests.back().file + ":" + (o.tare ? " force " + common::short_number(off.force_n) + " N" : "") +
                 (o.zero_displacement ? " displacement " + common::short_number(off.displacement_m) + " m" : "");
    if (!names.insert(d.tests.back().file).second)
      throw InputError(f, 0, "", "a second export named " + d.tests.back().file + ": each test is written under its file's name");
  }
  const bool shear = o.mode == Mode::simple_shear;
  const std::string gauge = shear ? "thickness_m" : "length_m", area = shear ? "length_m x width_m" : "width_m x thickness_m";
  d.import_note = "viscera-lab import: time_s = '" + o.time.name + "' [" + o.time.unit + "] x " + common::short_number(o.time.to_si) +
                  "; strain = '" + o.displacement.name + "' [" + o.displacement.unit + "] x " + common::short_number(o.displacement.to_si) +
                  " / specimen." + gauge + "; stress_pa = '" + o.force.name + "' [" + o.force.unit + "] x " + common::short_number(o.force.to_si) +
                  " / (specimen." + area + ")";
  if (o.tare) d.import_note += "; tare: each test's force at rest (its leading rows before the displacement moves) subtracted (a preload)";
  if (o.zero_displacement) d.import_note += "; displacement from each test's first row";
  if (o.compression_positive) d.import_note += "; compression positive in the exports: force and displacement negated";
  if (o.platens) d.import_note += "; between platens (contact: platens)";
  if (o.history == History::reset) d.import_note += "; each test on an untouched specimen (history: reset)";
  if (!o.specimen_of.empty())
    d.import_note +=
        "; " + std::to_string(o.specimen_of.size()) + " tests on their own specimens (each test's \"specimen\"; its geometry converts it)";
  if (!offsets.empty()) d.import_note += " (taken off: " + offsets + ")";
  write_dataset(d, folder);
  return read_dataset(folder);
}

}  // namespace viscera::lab
