#include "report.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "viscera/common/file_bytes.hpp"
#include "viscera/lab/fit.hpp"
#include "viscera/lab/material_export.hpp"
#include "viscera/lab/model_file.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/report_json.hpp"
#include "viscera/lab/stress_controlled.hpp"
#include "viscera/plot/svg_plot.hpp"

namespace viscera::lab {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

std::string stem(const std::string& file) { return fs::path(file).stem().string(); }

void md_noise(std::ostream& md, const Analysis& a, double seconds) {
  md << "Noise level of the data (RMS of `stress_sd_pa`, or estimated from second differences; for a stress-controlled test that of its strain, as "
        "an equivalent stress): "
     << a.noise_pa << " Pa. ";
  if (const NoiseCheck& c = a.noise_check; c.tests > 0)
    md << "Checked by a second path, the spread in " << c.holds << " holds of " << c.tests << " tests about a running mean over " << c.window_s
       << " s: " << c.holds_pa << " Pa against " << c.first_pa << " Pa by the first on the same tests"
       << (c.agree ? " (they agree within a factor of 2). " : " (**they disagree** by more than a factor of 2: see the verdict). ");
  else
    md << "No test holds its command long enough to check the noise by a second path. ";
  md << "Analysis time: " << seconds << " s.\n\n";
  for (const auto& line : a.decimated) md << "Decimated for the fit and the plots: " << line << ".\n\n";
}

void md_errors(std::ostream& md, const Analysis& a, const Dataset& d) {
  md << "## Errors per test (RMS, Pa)\n\n| test | noise | baseline fit | baseline held-out | final fit | final held-out "
        "|\n|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < a.baseline.tests.size(); ++k)
    md << "| " << a.baseline.tests[k].file << " | " << a.baseline.tests[k].noise_pa << " | " << a.baseline.tests[k].fit_rms_pa << " | "
       << a.baseline.tests[k].heldout_rms_pa << " | " << a.final.tests[k].fit_rms_pa << " | " << a.final.tests[k].heldout_rms_pa << " |\n";
  md << "| **all (RMS over tests)** | " << a.noise_pa << " | " << a.baseline.fit_rms_pa << " | " << a.baseline.heldout_rms_pa << " | "
     << a.final.fit_rms_pa << " | " << a.final.heldout_rms_pa << " |\n\n";
  md << "Held-out: the model is fitted to the other tests only and predicts this one. A stress-controlled test is simulated "
        "under its measured stress and judged on the strain it measured; its figures here are the strain errors times its apparent "
        "modulus (largest stress over largest strain), an equivalent stress:\n\n";
  for (std::size_t k = 0; k < a.baseline.tests.size(); ++k)
    if (d.tests[k].control == Control::stress)
      md << "- " << a.baseline.tests[k].file << " in strain: noise " << a.baseline.tests[k].noise_strain << ", baseline held-out "
         << a.baseline.tests[k].heldout_rms_strain << ", final held-out " << a.final.tests[k].heldout_rms_strain << "\n";
  md << "\n";
}

void md_nested(std::ostream& md, const Analysis& a) {
  if (!a.nested.empty()) {
    md << "## The honest gain: nested leave-one-out\n\nThe gain above is measured on held-out tests, but every test had a say in which "
          "mechanisms were chosen. Here the whole selection runs once per test without it; the model it chooses, fitted without the "
          "test, predicts it. Held-out RMS over tests that played no part in choosing: **"
       << a.nested_heldout_rms_pa << " Pa, gain " << a.nested_gain << "x** (against " << a.final.heldout_rms_pa << " Pa, gain " << a.gain
       << "x, for the model chosen on all tests).\n\n| left out | mechanisms chosen without it | its error [Pa] |\n|---|---|---|\n";
    for (const auto& f : a.nested) {
      md << "| " << f.file << " | ";
      for (std::size_t k = 0; k < f.causes.size(); ++k) md << (k ? ", " : "") << name(f.causes[k]);
      md << (f.causes.empty() ? "none" : "") << " | " << f.heldout_rms_pa << " |\n";
    }
    md << "\n";
  } else if (!a.nested_not_run.empty()) {
    md << "## The honest gain: not measured\n\n"
       << a.nested_not_run << ". Every test had a say in which mechanisms were chosen, so "
       << "the gain above is optimistic and the causes are tentative.\n\n";
  }
}

void md_candidates(std::ostream& md, const Analysis& a) {
  md << "## Candidate mechanisms\n\n| round | mechanism | held-out RMS before | after | accepted | evidence in the residuals "
        "|\n|---|---|---|---|---|---|\n";
  for (const auto& c : a.candidates)
    md << "| " << c.round << " | " << name(c.mechanism) << " | " << c.heldout_before_pa << " | " << c.heldout_after_pa << " | "
       << (c.accepted ? "yes" : "no") << " | " << c.evidence << " |\n";
  md << "\nA mechanism is accepted when it lowers the held-out mean square error by more than half the noise variance and the "
        "held-out RMS by at least 5%; rounds add the best accepted mechanism and try the rest on top.\n\n";
}

void md_adequacy(std::ostream& md, const Analysis& a) {
  const Adequacy& q = a.adequacy;
  md << "## Does the model explain the data?\n\n"
     << (q.explained ? "**Yes**" : "**No**") << ": the residual of the model the analysis stands by (fitted to all tests) is " << q.residual_to_noise
     << "x the noise over the tests. Explained means at most " << kAdequacyFactor << "x over the tests and " << kAdequacyTestFactor
     << "x on every strain-controlled test (a stress-controlled test's strain error, times its apparent modulus, is shown but not "
        "judged alone).\n\n| test | residual / noise | mean / noise | began in the session [s] |\n|---|---|---|---|\n";
  for (const auto& t : q.tests)
    md << "| " << t.file << (t.judged ? "" : " (stress control)") << " | " << t.residual_to_noise << " | " << t.mean_to_noise << " | "
       << t.session_start_s << " |\n";
  md << "\n| phase | residual / noise | samples |\n|---|---|---|\n";
  for (const auto& p : q.phases) md << "| " << p.phase << " | " << p.rms_to_noise << " | " << p.samples << " |\n";
  md << "\nCorrelation of the squared residual with the strain amplitude " << q.correlation_amplitude << ", with log |strain rate| "
     << q.correlation_rate << "; of the signed residual with the time since the session began " << q.correlation_session_time
     << "; mean residual where the command is back at zero after a large excursion " << q.set_at_zero_to_noise << "x the noise (" << q.set_samples
     << " samples).\n\n";
  for (const auto& f : q.findings) md << "- " << f << "\n";
  md << (q.findings.empty() ? "" : "\n");
}

void md_parameters(std::ostream& md, const Analysis& a) {
  const ParameterUncertainty& u = a.uncertainty;
  md << "## Parameters and their uncertainty\n\n" << u.method << ".";
  if (!u.not_run.empty()) md << " Not measured: " << u.not_run << ".";
  if (u.replicates > 0 && u.same_form != u.replicates)
    md << " The stiffening form was chosen again in " << u.same_form << " of " << u.replicates << " draws; B's figures come from those.";
  md << "\n\n| parameter | value | standard error | 95% interval | determined by the data |\n|---|---|---|---|---|\n";
  for (const auto& p : u.parameters) {
    md << "| " << p.name << " [" << p.unit << "] | " << p.value << " | ";
    if (u.replicates > 0)
      md << p.standard_error << " | " << p.low << " to " << p.high << " | " << (p.determined ? "yes" : "**no**") << " |\n";
    else
      md << "- | - | - |\n";
  }
  md << "\n";
}

void md_specimen(std::ostream& md, const Analysis& a) {
  md << "## On the tetrahedral specimen\n\nEach model also runs on the specimen meshed with tetrahedra (viscera's GPS with memory "
        "variables, backward Euler with adaptive steps, inertia from the specimen's density), driven by the measured history. "
        "For stress-controlled tests both columns are the strain error times the test's apparent modulus.\n\n";
  for (const auto& c : a.specimen) {
    md << "- `" << c.model << "`: ";
    if (!c.ran) {
      md << c.note << "\n";
      continue;
    }
    md << c.steps << " implicit steps, " << c.newton_iterations << " Newton iterations" << (c.note.empty() ? "" : "; " + c.note) << "\n\n"
       << "  | test | RMS on the specimen [Pa] | RMS of the material-point law [Pa] |\n  |---|---|---|\n";
    for (std::size_t k = 0; k < c.files.size(); ++k)
      md << "  | " << c.files[k] << " | " << c.specimen_rms_pa[k] << " | " << c.law_rms_pa[k] << " |\n";
    md << "\n";
  }
}

/// A test's two plots (data and models; residuals) and their section of report.md.
void md_test_plots(std::ostream& md, const Analysis& a, const TestData& t, const std::string& out_dir) {
  // What the test measured: stress under strain control, strain under stress control.
  const bool strain_measured = t.control == Control::stress;
  const std::vector<double>& data = strain_measured ? t.strain : t.stress_pa;
  const std::string quantity = strain_measured ? "strain" : "stress", unit = strain_measured ? "strain [-]" : "stress [Pa]";
  const auto yb = predict_measured(a.baseline.model, t), yf = predict_measured(a.final.model, t);
  std::vector<double> rb, rf;
  for (std::size_t i = 0; i < yb.size(); ++i) {
    rb.push_back(data[i] - yb[i]);
    rf.push_back(data[i] - yf[i]);
  }
  const std::string name_fit = stem(t.file) + "_fit.svg", name_res = stem(t.file) + "_residual.svg";
  // Time since the first sample (plus one sampling interval), on a log axis: ramps and holds
  // that last from 0.1 s to minutes are all visible.
  std::vector<double> since;
  const double offset = t.time_s[1] - t.time_s[0];
  for (double x : t.time_s) since.push_back(x - t.time_s[0] + offset);
  plot::Figure fit{t.file + ": " + quantity + ", data and models (fitted to all tests)",
                   "time since the first sample [s] (log)",
                   unit,
                   {{"data", since, data, "#000000", "", 2.0},
                    {"baseline (" + std::to_string(a.baseline.model.parameter_count()) + " parameters)", since, yb, "#1f77b4", "8 4", 1.6},
                    {"final (" + std::to_string(a.final.model.parameter_count()) + " parameters)", since, yf, "#d62728", "", 1.6}}};
  fit.log_x = true;
  plot::write_svg((fs::path(out_dir) / name_fit).string(), fit);
  plot::Figure res{t.file + ": residual (data - model)",
                   "time since the first sample [s] (log)",
                   "residual, " + unit,
                   {{"baseline", since, rb, "#1f77b4", "8 4", 1.6}, {"final", since, rf, "#d62728", "", 1.6}}};
  res.log_x = true;
  plot::write_svg((fs::path(out_dir) / name_res).string(), res);
  md << "### " << t.file << " (" << to_string(t.control) << " control)\n\n![" << t.file << "](" << name_fit << ")\n\n![residual](" << name_res
     << ")\n\n";
}

}  // namespace

void write_report(const Analysis& a, const Dataset& d, const std::string& out_dir, double seconds) {
  common::create_output_folder(out_dir, "--out");
  const MaterialFiles files = material_files(a, d);
  const std::string &material = files.material, &baseline = files.baseline, &why = files.why, &note = files.note;
  const auto out = [&](const char* name) { return (fs::path(out_dir) / name).string(); };
  if (!material.empty()) common::write_file_text(out("material.json"), material);
  if (!baseline.empty()) common::write_file_text(out("material-baseline.json"), baseline);
  common::write_file_text(out("report.json"), report_json(a, d, seconds, files).dump(2) + "\n");
  write_model((fs::path(out_dir) / "model.json").string(), a.supported_model(), a.dataset);

  std::ostringstream md;
  md << "# viscera-lab report: " << a.dataset << "\n\n" << a.verdict << "\n\n";
  md_noise(md, a, seconds);
  md_errors(md, a, d);
  md_nested(md, a);
  md_adequacy(md, a);
  md_parameters(md, a);
  md_candidates(md, a);
  md_specimen(md, a);
  md << "\n## Models\n\n- baseline: `" << a.baseline.model.describe() << "`, E = " << a.baseline.model.modulus_pa
     << " Pa, eta = " << a.baseline.model.viscosity_pa_s << " Pa s\n- final: `" << a.final.model.describe() << "` (parameters in `model.json`)\n\n";
  md << "The organ's material file: "
     << (material.empty() ? "not written: " + why
                          : std::string("`material.json` (docs/MATERIAL.md, model `relaxation_spectrum`): the model above in the server's GPS, its "
                                        "elastic shape calibrated on this specimen; a scene names it as its material"))
     << (baseline.empty() ? std::string() : "; the baseline's, the linear tissue to compare it with: `material-baseline.json`")
     << (note.empty() ? std::string() : " (" + note + ")") << ".\n\n";
  md << "## Data, baseline and final model\n\n";
  for (const TestData& t : d.tests) md_test_plots(md, a, t, out_dir);
  common::write_file_text(out("report.md"), md.str());
}

void write_prediction(const MaterialModel& m, const std::string& model_path, const Dataset& d, const std::string& out_dir) {
  common::create_output_folder(out_dir, "--out");
  common::write_file_text((fs::path(out_dir) / "report.json").string(), prediction_json(m, model_path, d).dump(2) + "\n");
}

}  // namespace viscera::lab
