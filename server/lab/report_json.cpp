#include "viscera/lab/report_json.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include "viscera/lab/fit.hpp"
#include "viscera/lab/material_export.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/stress_controlled.hpp"

namespace viscera::lab {

using nlohmann::json;

namespace {

json figures(const ModelEvaluation& e) {
  json j;
  j["model"] = e.model.describe();
  j["fit_rms_pa"] = e.fit_rms_pa;
  j["heldout_rms_pa"] = e.heldout_rms_pa;
  j["parameters"] = e.model.parameter_count();
  j["tests"] = json::array();
  for (const auto& t : e.tests) {
    json jt{{"file", t.file}, {"fit_rms_pa", t.fit_rms_pa}, {"heldout_rms_pa", t.heldout_rms_pa}, {"noise_pa", t.noise_pa}};
    if (t.noise_strain > 0 || t.heldout_rms_strain > 0) {  // stress-controlled: the measured quantity is the strain
      jt["fit_rms_strain"] = t.fit_rms_strain;
      jt["heldout_rms_strain"] = t.heldout_rms_strain;
      jt["noise_strain"] = t.noise_strain;
    }
    j["tests"].push_back(jt);
  }
  return j;
}

json noise_json(const Analysis& a) {
  const NoiseCheck& c = a.noise_check;
  json n{{"estimate_pa", a.noise_pa},
         {"method",
          "RMS over tests of stress_sd_pa where given, else the second differences of the measured quantity (median absolute "
          "value, the SD for white noise)"},
         {"tests_with_holds", c.tests}};
  if (c.tests > 0) {
    n["first_estimate_on_those_tests_pa"] = c.first_pa;
    n["second_estimate_pa"] = c.holds_pa;
    n["second_method"] = "spread of the measured quantity in " + std::to_string(c.holds) + " holds about a running mean over " +
                         std::to_string(c.window_s) + " s (robust SD, first window of each hold left out)";
    n["ratio"] = c.holds_pa / std::max(c.first_pa, 1e-300);
    n["agree_within_factor"] = kNoiseAgreementFactor;
  }
  n["agree"] = c.agree;
  return n;
}

json names_json(const std::vector<Mechanism>& ms) {
  json l = json::array();
  for (Mechanism m : ms) l.push_back(name(m));
  return l;
}

json nested_json(const Analysis& a) {
  if (a.nested.empty()) return {{"ran", false}, {"why", a.nested_not_run}};
  json n{{"ran", true}, {"heldout_rms_pa", a.nested_heldout_rms_pa}, {"gain", a.nested_gain}, {"folds", json::array()}};
  for (const auto& f : a.nested) n["folds"].push_back({{"left_out", f.file}, {"causes", names_json(f.causes)}, {"heldout_rms_pa", f.heldout_rms_pa}});
  return n;
}

json specimen_json(const Analysis& a) {
  json out = json::array();
  for (const auto& c : a.specimen) {
    json jc{{"model", c.model}, {"ran", c.ran}, {"note", c.note}, {"steps", c.steps}, {"newton_iterations", c.newton_iterations}};
    jc["tests"] = json::array();
    for (std::size_t k = 0; k < c.files.size(); ++k)
      jc["tests"].push_back({{"file", c.files[k]}, {"specimen_rms_pa", c.specimen_rms_pa[k]}, {"law_rms_pa", c.law_rms_pa[k]}});
    out.push_back(jc);
  }
  return out;
}

json adequacy_json(const Adequacy& q) {
  json j{{"explained", q.explained},
         {"residual_to_noise", q.residual_to_noise},
         {"rule", "explained when the residual of the model fitted to all tests is at most " + std::to_string(kAdequacyFactor) +
                      "x the noise over the tests (RMS) and at most " + std::to_string(kAdequacyTestFactor) + "x on every strain-controlled test"},
         {"tests", json::array()},
         {"phases", json::array()},
         {"correlation_with_strain_amplitude", q.correlation_amplitude},
         {"correlation_with_log_strain_rate", q.correlation_rate},
         {"correlation_with_session_time", q.correlation_session_time},
         {"set_at_zero_to_noise", q.set_at_zero_to_noise},
         {"set_samples", q.set_samples},
         {"findings", q.findings}};
  for (const auto& t : q.tests)
    j["tests"].push_back({{"file", t.file},
                          {"residual_to_noise", t.residual_to_noise},
                          {"mean_to_noise", t.mean_to_noise},
                          {"session_start_s", t.session_start_s},
                          {"judged", t.judged}});
  for (const auto& p : q.phases) j["phases"].push_back({{"phase", p.phase}, {"residual_to_noise", p.rms_to_noise}, {"samples", p.samples}});
  return j;
}

json uncertainty_json(const ParameterUncertainty& u) {
  json j{{"method", u.method}, {"replicates", u.replicates}, {"parameters", json::array()}};
  if (!u.not_run.empty()) j["not_run"] = u.not_run;
  if (u.replicates > 0 && u.same_form != u.replicates) j["draws_with_the_same_stiffening_form"] = u.same_form;
  for (const auto& p : u.parameters) {
    json jp{{"name", p.name}, {"unit", p.unit}, {"value", p.value}};
    if (u.replicates > 0) {
      jp["standard_error"] = p.standard_error;
      jp["interval_95"] = {p.low, p.high};
      jp["determined"] = p.determined;
    }
    j["parameters"].push_back(jp);
  }
  return j;
}

}  // namespace

MaterialFiles material_files(const Analysis& a, const Dataset& d) {
  MaterialFiles f;
  f.material = material_file_text(a.supported_model(), d, a.dataset + " (viscera-lab)", &f.why, &f.note);
  f.baseline = material_file_text(a.baseline.model, d, a.dataset + " (viscera-lab, linear baseline)", &f.why_baseline);
  return f;
}

json report_json(const Analysis& a, const Dataset& d, double seconds, const MaterialFiles& files) {
  json j;
  j["dataset"] = a.dataset;
  j["mode"] = to_string(d.mode);
  j["history"] = to_string(d.history);
  j["noise_pa"] = a.noise_pa;
  j["noise"] = noise_json(a);
  j["baseline"] = figures(a.baseline);
  j["final"] = figures(a.final);
  j["causes"] = names_json(a.named_causes());  // found (or tentative); none when the honest gain did not hold
  j["causes_status"] = to_string(a.causes_status);
  j["causes_chosen_on_all_tests"] = names_json(a.causes);
  j["gain"] = a.gain;
  if (!a.nested.empty() || !a.nested_not_run.empty()) j["nested_leave_one_out"] = nested_json(a);
  j["candidates"] = json::array();
  for (const auto& c : a.candidates)
    j["candidates"].push_back({{"mechanism", name(c.mechanism)},
                               {"round", c.round},
                               {"heldout_rms_before_pa", c.heldout_before_pa},
                               {"heldout_rms_after_pa", c.heldout_after_pa},
                               {"accepted", c.accepted},
                               {"evidence", c.evidence}});
  j["adequacy"] = adequacy_json(a.adequacy);
  j["parameters"] = uncertainty_json(a.uncertainty);
  j["verdict"] = a.verdict;
  j["specimen"] = specimen_json(a);
  j["seconds"] = seconds;
  j["decimated"] = a.decimated;
  j["material_file"] = files.material.empty() ? json{{"written", false}, {"why", files.why}} : json{{"written", true}, {"file", "material.json"}};
  if (!files.baseline.empty()) j["material_file"]["baseline_file"] = "material-baseline.json";
  if (!files.note.empty()) j["material_file"]["note"] = files.note;
  return j;
}

json prediction_json(const MaterialModel& model, const std::string& model_path, const Dataset& d) {
  // Ogden's form responds as the data's mode loads it, and platens never pull, whatever data set
  // the model came from.
  const MaterialModel m = for_dataset(model, d);
  json j;
  j["model"] = m.describe();
  j["model_file"] = model_path;
  j["dataset"] = d.name;
  j["tests"] = json::array();
  double s = 0;
  for (const auto& t : d.tests) {
    const double r = rms_error_pa(m, t);
    s += r * r;
    json jt{{"file", t.file}, {"rms_pa", r}};
    if (t.control == Control::stress) jt["rms_strain"] = rms_error_measured(m, t);
    j["tests"].push_back(jt);
  }
  j["rms_pa"] = std::sqrt(s / static_cast<double>(d.tests.size()));
  return j;
}

}  // namespace viscera::lab
