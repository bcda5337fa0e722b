#include "dataset.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "common/known_fields.hpp"

namespace viscera::lab {

using tissue::InputError;
using nlohmann::json;

const char* to_string(Mode m) { return m == Mode::uniaxial ? "uniaxial" : "simple_shear"; }
const char* to_string(Control c) { return c == Control::strain ? "strain" : "stress"; }

namespace {

double positive(const json& j, const char* key, const std::string& source, double lo, double hi, const char* unit) {
  const std::string field = std::string("specimen.") + key;
  if (!j.contains(key)) throw InputError(source, 0, field, "missing");
  if (!j[key].is_number()) throw InputError(source, 0, field, j[key].dump() + " is not a number");
  const double v = j[key].get<double>();
  if (!(v >= lo && v <= hi)) {
    std::ostringstream s;
    s << v << " " << unit << " cannot be right (expected " << lo << " to " << hi << ")";
    throw InputError(source, 0, field, s.str());
  }
  return v;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ')) cell.pop_back();
    while (!cell.empty() && cell.front() == ' ') cell.erase(cell.begin());
    out.push_back(cell);
  }
  return out;
}

TestData read_csv(const std::string& path, const std::string& file, Control control) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open file");
  std::string line;
  if (!std::getline(in, line)) throw InputError(path, 1, "header", "file is empty");
  const auto header = split(line);
  int col_t = -1, col_e = -1, col_s = -1, col_sd = -1;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] == "time_s") col_t = static_cast<int>(c);
    else if (header[c] == "strain") col_e = static_cast<int>(c);
    else if (header[c] == "stress_pa") col_s = static_cast<int>(c);
    else if (header[c] == "stress_sd_pa") col_sd = static_cast<int>(c);
  }
  for (const auto& [col, name] : {std::pair{col_t, "time_s"}, std::pair{col_e, "strain"}, std::pair{col_s, "stress_pa"}})
    if (col < 0) throw InputError(path, 1, name, "column missing (header: " + line + ")");
  TestData t;
  t.file = file;
  t.control = control;
  long row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty() || line == "\r") continue;
    const auto cells = split(line);
    const auto value = [&](int col, const char* name) {
      if (col >= static_cast<int>(cells.size())) throw InputError(path, row, name, "missing value");
      const std::string& c = cells[static_cast<std::size_t>(col)];
      double v = 0;
      const auto [end, ec] = std::from_chars(c.data(), c.data() + c.size(), v);
      if (ec != std::errc() || end != c.data() + c.size()) throw InputError(path, row, name, "'" + c + "' is not a number");
      if (!std::isfinite(v)) throw InputError(path, row, name, "'" + c + "' is not finite");
      return v;
    };
    const double time = value(col_t, "time_s"), strain = value(col_e, "strain"), stress = value(col_s, "stress_pa");
    if (!t.time_s.empty() && !(time > t.time_s.back())) {
      std::ostringstream s;
      s << time << " s does not increase (previous row " << t.time_s.back() << " s)";
      throw InputError(path, row, "time_s", s.str());
    }
    if (std::abs(strain) > 5.0)
      throw InputError(path, row, "strain", std::to_string(strain) + " cannot be right: strain is dimensionless (1 = 100%), not percent");
    if (std::abs(stress) > 1e9)
      throw InputError(path, row, "stress_pa", std::to_string(stress) + " Pa cannot be right for soft tissue (stress in pascals?)");
    t.time_s.push_back(time);
    t.strain.push_back(strain);
    t.stress_pa.push_back(stress);
    if (col_sd >= 0) {
      const double sd = value(col_sd, "stress_sd_pa");
      if (sd < 0) throw InputError(path, row, "stress_sd_pa", std::to_string(sd) + " is negative");
      t.stress_sd_pa.push_back(sd);
    }
  }
  if (t.time_s.size() < 3) throw InputError(path, row, "", "fewer than 3 data rows");
  return t;
}

}  // namespace

Dataset read_dataset(const std::string& folder) {
  const std::string meta = (std::filesystem::path(folder) / "dataset.json").string();
  std::ifstream in(meta);
  if (!in) throw InputError(meta, 0, "", "cannot open file (is " + folder + " a data set folder?)");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw InputError(meta, 0, "JSON", e.what());
  }
  if (!j.is_object()) throw InputError(meta, 0, "", "not a JSON object");
  tissue::require_known_fields(j, meta, "", {"name", "mode", "specimen", "tests"});
  const auto text = [&](const json& o, const char* key, const std::string& field) {
    if (!o.contains(key)) return std::string();
    if (!o[key].is_string()) throw InputError(meta, 0, field, o[key].dump() + " is not a string");
    return o[key].get<std::string>();
  };
  Dataset d;
  d.folder = folder;
  d.name = text(j, "name", "name");
  if (d.name.empty()) d.name = std::filesystem::path(folder).filename().string();
  const std::string mode = text(j, "mode", "mode");
  if (mode == "uniaxial") d.mode = Mode::uniaxial;
  else if (mode == "simple_shear") d.mode = Mode::simple_shear;
  else throw InputError(meta, 0, "mode", "'" + mode + "' is not uniaxial or simple_shear");
  if (!j.contains("specimen") || !j["specimen"].is_object()) throw InputError(meta, 0, "specimen", "missing or not an object");
  const json& s = j["specimen"];
  tissue::require_known_fields(s, meta, "specimen.", {"length_m", "width_m", "thickness_m", "density_kg_m3"});
  d.specimen = {positive(s, "length_m", meta, 1e-6, 10, "m"), positive(s, "width_m", meta, 1e-6, 10, "m"),
                positive(s, "thickness_m", meta, 1e-6, 10, "m"), positive(s, "density_kg_m3", meta, 1, 1e5, "kg/m^3")};
  if (!j.contains("tests") || !j["tests"].is_array() || j["tests"].empty()) throw InputError(meta, 0, "tests", "missing or empty");
  for (std::size_t k = 0; k < j["tests"].size(); ++k) {
    const json& t = j["tests"][k];
    const std::string field = "tests[" + std::to_string(k) + "]";
    if (!t.is_object() || !t.contains("file") || !t["file"].is_string()) throw InputError(meta, 0, field + ".file", "missing");
    tissue::require_known_fields(t, meta, field + ".", {"file", "control"});
    const std::string control = text(t, "control", field + ".control");
    if (control != "strain" && control != "stress")
      throw InputError(meta, 0, field + ".control", "'" + control + "' is not strain or stress");
    const std::string file = t["file"].get<std::string>();
    d.tests.push_back(read_csv((std::filesystem::path(folder) / file).string(), file,
                               control == "strain" ? Control::strain : Control::stress));
  }
  return d;
}

void write_dataset(const Dataset& d, const std::string& folder) {
  std::filesystem::create_directories(folder);
  json j;
  j["name"] = d.name;
  j["mode"] = to_string(d.mode);
  j["specimen"] = {{"length_m", d.specimen.length_m}, {"width_m", d.specimen.width_m},
                   {"thickness_m", d.specimen.thickness_m}, {"density_kg_m3", d.specimen.density_kg_m3}};
  j["tests"] = json::array();
  for (const auto& t : d.tests) {
    j["tests"].push_back({{"file", t.file}, {"control", to_string(t.control)}});
    std::ofstream csv(std::filesystem::path(folder) / t.file);
    csv.precision(10);
    csv << "time_s,strain,stress_pa" << (t.stress_sd_pa.empty() ? "" : ",stress_sd_pa") << "\n";
    for (std::size_t k = 0; k < t.time_s.size(); ++k) {
      csv << t.time_s[k] << ',' << t.strain[k] << ',' << t.stress_pa[k];
      if (!t.stress_sd_pa.empty()) csv << ',' << t.stress_sd_pa[k];
      csv << '\n';
    }
  }
  std::ofstream(std::filesystem::path(folder) / "dataset.json") << j.dump(2) << "\n";
}

}  // namespace viscera::lab
