// viscera._viscera.lab: viscera-lab's data sets, analysis and prediction, with the report as the  // SPDX-License-Identifier: Apache-2.0
// program writes it (report_json.hpp), parsed into Python objects by the package.
#include <chrono>
#include <filesystem>

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/lab/analysis.hpp"
#include "viscera/lab/decimation.hpp"
#include "viscera/lab/model_file.hpp"
#include "viscera/lab/report_json.hpp"
#include "viscera/lab/stress_controlled.hpp"

#include "bindings.hpp"
#include "numpy_views.hpp"

namespace viscera::python {

namespace {

using namespace viscera::lab;

/// An analysis with the data set it ran on (decimated as it was fitted) and its report.
struct AnalysisResult {
  Dataset dataset;  ///< as fitted (decimated)
  Analysis analysis;
  MaterialFiles files;
  std::string report_json;
};

py::array_t<double> copy_of(const std::vector<double>& v) { return owning_array(std::vector<double>(v)); }

const TestData& test_named(const Dataset& d, const std::string& file) {
  for (const auto& t : d.tests)
    if (t.file == file) return t;
  std::string names;
  for (const auto& t : d.tests) names += (names.empty() ? "" : ", ") + t.file;
  throw common::InputError(d.folder, 0, "test", "'" + file + "' is not one of " + names);
}

}  // namespace

void bind_lab(py::module_& m) {
  py::class_<TestData>(m, "Test", "One test of a data set: time [s], strain [-], stress [Pa], in SI units.")
      .def_readonly("file", &TestData::file, "the test's CSV file, as dataset.json names it")
      .def_property_readonly(
          "control", [](const TestData& t) { return std::string(to_string(t.control)); }, "strain (stress measured) or stress (strain measured)")
      .def_property_readonly(
          "time_s", [](const TestData& t) { return copy_of(t.time_s); }, "[s] time of each row")
      .def_property_readonly(
          "strain", [](const TestData& t) { return copy_of(t.strain); }, "engineering strain [-] of each row")
      .def_property_readonly(
          "stress_pa", [](const TestData& t) { return copy_of(t.stress_pa); }, "[Pa] stress of each row")
      .def_property_readonly(
          "stress_sd_pa", [](const TestData& t) { return copy_of(t.stress_sd_pa); },
          "[Pa] the stress's standard deviation per row (empty if not given)")
      .def_readonly("before_tension", &TestData::before_tension,
                    "the largest tension strain [-] its specimen went through in the tests before it (history carried)")
      .def_readonly("before_compression", &TestData::before_compression,
                    "the largest compression strain [-] (as a positive number) its specimen went through in the tests before it");
  py::class_<Dataset>(m, "Dataset", "A measured data set (dataset.json and one CSV per test).")
      .def_readonly("name", &Dataset::name, "its name")
      .def_readonly("folder", &Dataset::folder, "the data set's folder")
      .def_readonly("import_note", &Dataset::import_note, "how viscera-lab import made it, with its units (empty otherwise)")
      .def_property_readonly(
          "mode", [](const Dataset& d) { return std::string(to_string(d.mode)); }, "uniaxial or simple_shear")
      .def_property_readonly(
          "contact", [](const Dataset& d) { return std::string(d.platens ? "platens" : "bonded"); },
          "bonded, or platens (compressed between platens it was not bonded to: they cannot pull)")
      .def_property_readonly(
          "history", [](const Dataset& d) { return std::string(to_string(d.history)); },
          "carried (the tests on one specimen in the listed order, each starting where the last left it) or reset")
      .def_readonly("tests", &Dataset::tests, "the tests, in dataset.json's order");
  m.def("read_dataset", &read_dataset, py::arg("folder"),
        "Reads DATASET_DIR/dataset.json and its CSVs; raises InputError naming file, line and field.");

  py::class_<AnalysisResult>(m, "Analysis", "viscera-lab analyze's result.")
      .def_property_readonly("report_json", [](const AnalysisResult& r) { return r.report_json; })
      .def_property_readonly("material_file", [](const AnalysisResult& r) { return r.files.material; })
      .def_property_readonly("baseline_material_file", [](const AnalysisResult& r) { return r.files.baseline; })
      .def_property_readonly("dataset", [](const AnalysisResult& r) { return r.dataset; })
      .def(
          "predict",
          [](const AnalysisResult& r, const std::string& file, const std::string& which) {
            const MaterialModel* model = which == "baseline" ? &r.analysis.baseline.model
                                         : which == "final"  ? &r.analysis.final.model
                                         : which == "supported"
                                             ? &r.analysis.supported_model()
                                             : throw common::UsageError("model: '" + which + "' is not baseline, final or supported");
            const TestData& t = test_named(r.dataset, file);
            std::vector<double> y;
            {
              py::gil_scoped_release unlocked;
              y = predict_measured(*model, t);
            }
            return owning_array(std::move(y));
          },
          py::arg("test"), py::arg("model") = "supported",
          "The measured quantity of a test as a model predicts it: stress [Pa] (strain control) or strain (stress control).")
      .def(
          "write_model",
          [](const AnalysisResult& r, const std::string& path) {
            // Never over the data set it was fitted to (its dataset.json and CSVs), as the command line.
            std::vector<std::string> inputs{(std::filesystem::path(r.dataset.folder) / "dataset.json").string()};
            for (const TestData& t : r.dataset.tests) inputs.push_back((std::filesystem::path(r.dataset.folder) / t.file).string());
            common::refuse_overwrite(path, inputs, "write_model's path");
            write_model(path, r.analysis.supported_model(), r.analysis.dataset);
          },
          py::arg("path"), "Writes model.json (the model the analysis stands by), readable by predict and viscera-lab predict.");

  m.def(
      "analyze",
      [](const Dataset& d, bool specimen, bool nested, int bootstrap_replicates, std::size_t max_fit_points,
         std::function<void(const std::string&)> progress) {
        AnalyzeOptions o;
        o.specimen = specimen;
        o.nested = nested;
        o.bootstrap_replicates = bootstrap_replicates;
        o.max_fit_points = max_fit_points;
        if (bootstrap_replicates < 0) throw common::UsageError("bootstrap_replicates must be at least 0");
        if (max_fit_points < 10) throw common::UsageError("max_fit_points must be at least 10");
        auto result = std::make_unique<AnalysisResult>();
        struct Interrupted {};
        try {
          py::gil_scoped_release unlocked;  // progress takes the lock back for each line
          const auto t0 = std::chrono::steady_clock::now();
          // Between stages: Ctrl-C (a signal Python raises) stops the analysis there.
          result->analysis = analyze(
              d,
              [&](const std::string& line) {
                py::gil_scoped_acquire locked;
                if (PyErr_CheckSignals() != 0) throw Interrupted{};
                if (progress) progress(line);
              },
              o);
          const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          result->dataset = decimate(d, o.max_fit_points);
          result->files = material_files(result->analysis, result->dataset);
          result->report_json = report_json(result->analysis, result->dataset, seconds, result->files).dump();
        } catch (const Interrupted&) {
          throw py::error_already_set();  // the KeyboardInterrupt the signal handler set
        }
        return result;
      },
      py::arg("dataset"), py::kw_only(), py::arg("specimen") = true, py::arg("nested") = true, py::arg("bootstrap_replicates") = 40,
      py::arg("max_fit_points") = 2000, py::arg("progress") = nullptr,
      "viscera-lab analyze: fits the baseline, names what it gets wrong and why, extends the model and measures the gain on "
      "held-out tests. progress(line) receives one line per stage. The interpreter lock is released meanwhile.");
  m.def(
      "predict",
      [](const std::string& model_path, const Dataset& d) {
        const MaterialModel model = read_model(model_path);
        py::gil_scoped_release unlocked;
        return prediction_json(model, model_path, d).dump();
      },
      py::arg("model_path"), py::arg("dataset"), "viscera-lab predict: per-test RMS errors of a model.json on a data set (report.json's text).");
}

}  // namespace viscera::python
