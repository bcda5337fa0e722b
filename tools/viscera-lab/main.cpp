// viscera-lab: confronts viscera's tissue model with measured data.  // SPDX-License-Identifier: Apache-2.0
//   viscera-lab analyze DATASET_DIR --out OUT_DIR
//   viscera-lab predict MODEL_JSON DATASET_DIR --out OUT_DIR
//   viscera-lab import EXPORT... --out DATASET_DIR --length-m L --width-m W --thickness-m T --time COL --force COL --displacement COL
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/lab/analysis.hpp"
#include "viscera/lab/decimation.hpp"
#include "viscera/lab/lab_import.hpp"
#include "viscera/lab/model_file.hpp"

#include "report.hpp"

using namespace viscera::lab;

namespace {

using viscera::common::UsageError;

/// The analysis's summary on standard output: the verdict, the causes, the figures.
void print_summary(const Analysis& a, double seconds, const std::string& out) {
  std::printf("%s\n", a.verdict.c_str());
  std::printf("causes (%s):", to_string(a.causes_status));
  for (Mechanism m : a.named_causes()) std::printf(" %s", name(m));
  if (a.causes_status == CausesStatus::not_confirmed) {
    std::printf(" none named; chosen on all tests but not held by the honest gain:");
    for (Mechanism m : a.causes) std::printf(" %s", name(m));
  }
  std::printf("%s\nbaseline held-out RMS %.4g Pa, final %.4g Pa, gain %.3gx, noise %.4g Pa; %.1f s; wrote %s/report.md and model.json\n",
              a.causes.empty() ? " none" : "", a.baseline.heldout_rms_pa, a.final.heldout_rms_pa, a.gain, a.noise_pa, seconds, out.c_str());
  std::printf("adequacy: %s (residual %.3gx the noise)%s\n", a.adequacy.explained ? "explained" : "not explained", a.adequacy.residual_to_noise,
              a.adequacy.explained ? "" : ": something outside the catalogue remains (report.md)");
  if (!a.nested.empty())
    std::printf("honest gain (nested leave-one-out: mechanisms chosen without the test predicted): %.3gx, held-out RMS %.4g Pa\n", a.nested_gain,
                a.nested_heldout_rms_pa);
  else
    std::printf("honest gain not measured: %s\n", a.nested_not_run.c_str());
}

void run_analyze(const std::vector<std::string>& positional, const std::string& out, bool quiet) {
  if (positional.size() != 2) throw UsageError("analyze takes one DATASET_DIR");
  const auto t0 = std::chrono::steady_clock::now();
  const Dataset d = read_dataset(positional[1]);
  if (!quiet) std::fprintf(stderr, "viscera-lab: %s: %zu tests, %s\n", d.name.c_str(), d.tests.size(), to_string(d.mode));
  const Analysis a = analyze(d, [&](const std::string& s) {
    if (!quiet) {
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "[%6.1f s] %s\n", el, s.c_str());
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_report(a, decimate(d, AnalyzeOptions{}.max_fit_points), out, seconds);  // plots of what was fitted
  print_summary(a, seconds, out);
  if (std::filesystem::exists(out + "/material.json"))
    std::printf("wrote %s/material.json: the model for the server's organs (a scene's \"material\", or viscera-control material --file)\n",
                out.c_str());
  if (std::filesystem::exists(out + "/material-baseline.json"))
    std::printf("wrote %s/material-baseline.json: the linear baseline's, to compare with\n", out.c_str());
}

void run_import(const std::vector<std::string>& positional, const std::string& out, const viscera::common::CommandLine& cl) {
  if (positional.size() < 2) throw UsageError("import takes one or more EXPORT files");
  const std::vector<std::string> files(positional.begin() + 1, positional.end());
  // Nothing import writes may be one of its inputs: any export, or the specimens table.
  std::vector<std::string> inputs = files;
  if (cl.has("specimens")) inputs.push_back(cl.text("specimens"));
  for (const auto& f : files) viscera::common::refuse_overwrite(out + "/" + std::filesystem::path(f).stem().string() + ".csv", inputs, "--out");
  ImportOptions o;
  o.name = cl.has("name") ? cl.text("name") : "";
  const std::string mode = cl.text("mode"), control = cl.text("control");
  if (mode != "uniaxial" && mode != "simple_shear") throw UsageError("--mode: '" + mode + "' is not uniaxial or simple_shear");
  if (control != "strain" && control != "stress") throw UsageError("--control: '" + control + "' is not strain or stress");
  o.mode = mode == "uniaxial" ? Mode::uniaxial : Mode::simple_shear;
  o.control = control == "strain" ? Control::strain : Control::stress;
  for (const char* required : {"length-m", "width-m", "thickness-m", "force", "displacement"})
    if (!cl.has(required)) throw UsageError(std::string("import needs --") + required);
  o.specimen = {cl.number_in("length-m", 1e-6, 10), cl.number_in("width-m", 1e-6, 10), cl.number_in("thickness-m", 1e-6, 10),
                cl.number_in("density-kg-m3", 1, 1e5)};
  o.time = parse_import_column("time", cl.text("time"), ImportQuantity::time);
  o.force = parse_import_column("force", cl.text("force"), ImportQuantity::force);
  o.displacement = parse_import_column("displacement", cl.text("displacement"), ImportQuantity::displacement);
  o.tare = cl.has("tare");
  o.zero_displacement = cl.has("zero-displacement");
  if (cl.has("specimens")) o.specimen_of = read_specimen_table(cl.text("specimens"), o.specimen);
  o.platens = cl.has("platens");
  const std::string history = cl.text("history");
  if (history != "carried" && history != "reset") throw UsageError("--history: '" + history + "' is not carried or reset");
  o.history = history == "carried" ? History::carried : History::reset;
  o.compression_positive = cl.has("compression-positive");
  const Dataset d = import_dataset(files, o, out);
  for (const auto& t : d.tests)
    std::printf("%s: %zu rows, %.4g s, strain %.4g to %.4g, stress %.4g to %.4g Pa\n", t.file.c_str(), t.time_s.size(),
                t.time_s.back() - t.time_s.front(), *std::min_element(t.strain.begin(), t.strain.end()),
                *std::max_element(t.strain.begin(), t.strain.end()), *std::min_element(t.stress_pa.begin(), t.stress_pa.end()),
                *std::max_element(t.stress_pa.begin(), t.stress_pa.end()));
  std::printf("wrote %s/dataset.json (%s)\n", out.c_str(), d.import_note.c_str());
}

void run_predict(const std::vector<std::string>& positional, const std::string& out) {
  if (positional.size() != 3) throw UsageError("predict takes MODEL_JSON and DATASET_DIR");
  const MaterialModel m = read_model(positional[1]);
  const Dataset d = read_dataset(positional[2]);
  write_prediction(m, positional[1], d, out);
  std::printf("wrote %s/report.json\n", out.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl(
      "viscera-lab",
      "analyze: fits the baseline (linear elasticity + Kelvin-Voigt damping) to the data set, shows where it is wrong\n"
      "  (per test, and on tests left out of the fit), names the cause among broadband_relaxation, strain_stiffening,\n"
      "  tension_compression_asymmetry, first_load_softening and, between platens, contact_take_up (a cause of the test, left\n"
      "  out of the material; accepted only if the held-out gain is clearly above the noise of the data), extends the model,\n"
      "  refits, and writes OUT_DIR/report.json, report.md (with SVG plots), model.json and material.json.\n"
      "predict: runs a fitted model.json on another data set and writes OUT_DIR/report.json with per-test RMS errors.\n"
      "import: turns a test machine's exports (one file per test: force and displacement over time, comma, semicolon or tab\n"
      "  separated, a header row naming the columns) into a data set in --out: strain = displacement / length (simple shear:\n"
      "  / thickness), stress = force / (width x thickness) (simple shear: / (length x width)); the conversion is written into\n"
      "  dataset.json. Columns as COLUMN:UNIT (time s|ms|min|h, force N|mN|kN, displacement m|mm|um).\n\n"
      "Data set format: README.md, section \"The data a user brings\". Units are SI. Progress lines go to stderr.");
  cl.usage(
      "viscera-lab analyze DATASET_DIR --out OUT_DIR\n       viscera-lab predict MODEL_JSON DATASET_DIR --out OUT_DIR\n"
      "       viscera-lab import EXPORT... --out DATASET_DIR --length-m L --width-m W --thickness-m T --time COLUMN[:UNIT]\n"
      "                          --force COLUMN[:UNIT] --displacement COLUMN[:UNIT] [--mode uniaxial|simple_shear] [--control strain|stress]\n"
      "                          [--specimens TABLE] [--tare] [--zero-displacement] [--platens] [--compression-positive]\n"
      "                          [--history carried|reset]");
  cl.flag("out", "DIR", "output folder (required)");
  cl.option_switch("quiet", "no progress lines");
  cl.option_switch("replace", "analyze, predict: write into an --out folder that holds files already (its files of the same names are replaced)");
  cl.flag("mode", "MODE", "import: uniaxial | simple_shear", "uniaxial");
  cl.flag("control", "C", "import: strain (displacement imposed) | stress (force imposed)", "strain");
  cl.flag("length-m", "L", "import: specimen length [m] (the gauge under uniaxial load)");
  cl.flag("width-m", "W", "import: specimen width [m]");
  cl.flag("thickness-m", "T", "import: specimen thickness [m] (the gauge in simple shear)");
  cl.flag("density-kg-m3", "RHO", "import: specimen density [kg/m^3]", "1060");
  cl.flag("time", "COLUMN[:UNIT]", "import: the time column, s | ms | min | h", "time:s");
  cl.flag("force", "COLUMN[:UNIT]", "import: the force column, N | mN | kN");
  cl.flag("displacement", "COLUMN[:UNIT]", "import: the displacement column (from the unloaded specimen), m | mm | um");
  cl.flag("name", "NAME", "import: the data set's name (default: the --out folder's)");
  cl.option_switch("tare",
                   "import: subtract each export's first force from its forces (a preload at the start: the test then starts at zero stress)");
  cl.option_switch("zero-displacement", "import: displacements from each export's first row, not from the export's own zero");
  cl.option_switch("platens",
                   "import: compressed between platens it is not bonded to (\"contact\": \"platens\"): the platens cannot pull, and the\n"
                   "  contact they take up at the start (a toe) is a candidate cause");
  cl.flag("specimens", "TABLE",
          "import: a CSV table of the specimens, a row per export: file (its file name) and any of length_m, width_m,\n"
          "  thickness_m, density_kg_m3 (an empty cell: the --length-m ... value); each test is converted with its own");
  cl.option_switch("compression-positive", "import: the exports count compression as positive force and displacement (both are negated)");
  cl.flag("history", "H",
          "import: carried (the exports, in the order given, are one specimen's session: each test starts where the last left it)\n"
          "  | reset (each test on an untouched specimen); a test with its own row in --specimens starts untouched either way",
          "carried");
  cl.allow_positional(1000);
  const auto usage_error = [](const std::string& what) {
    std::fprintf(stderr, "viscera-lab: %s (see --help)\n", what.c_str());
    return 2;
  };
  try {
    if (!cl.parse(argc, argv)) return 0;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-lab: %s\n", e.what());
    return 2;
  }
  const auto& positional = cl.positional();
  if (positional.empty()) return usage_error("missing command (analyze or predict)");
  if (!cl.has("out")) return usage_error("--out OUT_DIR is required");
  const std::string out = cl.text("out");
  const bool quiet = cl.has("quiet");
  try {
    // The report never goes over what the run reads: not into the data set's folder (its plots are
    // named after the tests), and not over the model predict reads.
    if (positional.size() >= 2) viscera::common::refuse_overwrite(out, {positional.back()}, "--out");
    // The folder made before the work: an analysis of minutes never fails at its end for want of it
    // (import makes its data set's folder itself, and refuses one that exists).
    if (positional[0] != "import") {
      viscera::common::refuse_existing_folder(out, cl.has("replace"), "--out");
      viscera::common::create_output_folder(out, "--out");
    }
    if (positional[0] == "predict" && positional.size() == 3)
      for (const char* written : {"report.json", "model.json"}) viscera::common::refuse_overwrite(out + "/" + written, {positional[1]}, "--out");
    if (positional[0] == "analyze")
      run_analyze(positional, out, quiet);
    else if (positional[0] == "import")
      run_import(positional, out, cl);
    else if (positional[0] == "predict")
      run_predict(positional, out);
    else
      return usage_error("unknown command '" + positional[0] + "'");
    return 0;
  } catch (const viscera::common::InputError& e) {
    std::fprintf(stderr, "viscera-lab: %s\n", e.what());
    return 2;
  } catch (const UsageError& e) {
    return usage_error(e.what());
  } catch (const std::exception& e) {  // a file system's refusal (a path too long to read): one line, never an abort
    std::fprintf(stderr, "viscera-lab: %s\n", e.what());
    return 1;
  }
}
