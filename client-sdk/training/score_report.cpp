#include "viscera/training/score_report.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cstdio>

namespace viscera::training {

namespace {
nlohmann::json point(const std::optional<protocol::Vector3>& p) { return p ? nlohmann::json::array({(*p)[0], (*p)[1], (*p)[2]}) : nlohmann::json(); }
}  // namespace

nlohmann::json to_json(const ScoreReport& r) {
  nlohmann::json criteria = nlohmann::json::array();
  for (const auto& c : r.criteria) {
    nlohmann::json j = {{"name", c.name}, {"value", c.value}, {"limit", c.limit}, {"unit", c.unit}, {"passed", c.passed}};
    if (!c.passed) j["why"] = c.why;
    criteria.push_back(std::move(j));
  }
  return {{"exercise", r.exercise},
          {"kind", r.kind},
          {"scene", r.scene},
          {"exercise_file", r.source},
          {"started", r.started},
          {"completed", r.completed},
          {"passed", r.passed},
          {"ending", r.ending},
          {"start_tick", r.start_tick},
          {"end_tick", r.end_tick},
          {"metrics",
           {{"time_s", r.time_s},
            {"force_samples", r.samples},
            {"force_samples_without_command", r.samples_without_command},
            {"undecodable_payloads", r.undecodable},
            {"path_length_m", r.path_length_m},
            {"peak_force_n", r.peak_force_n},
            {"mean_contact_force_n", r.mean_contact_force_n},
            {"time_above_force_limit_s", r.time_above_force_limit_s},
            {"max_edge_strain", r.max_edge_strain},
            {"max_tip_strain", r.max_tip_strain},
            {"longest_hold_s", r.longest_hold_s},
            {"drops", r.drops},
            {"mark_m", point(r.mark_m)},
            {"target_m", point(r.target_m)},
            {"mark_distance_m", r.mark_distance_m ? nlohmann::json(*r.mark_distance_m) : nlohmann::json()},
            {"incision_length_m", r.incision_length_m ? nlohmann::json(*r.incision_length_m) : nlohmann::json()},
            {"incision_deviation_m", r.incision_deviation_m},
            {"incision_mean_depth_m", r.incision_mean_depth_m},
            {"incision_max_depth_m", r.incision_max_depth_m},
            {"incision_cut_strain", r.incision_cut_strain}}},
          {"criteria", criteria},
          {"failures", r.failures}};
}

std::string to_markdown(const ScoreReport& r) {
  char b[512];
  std::string s = "# " + r.exercise + " (" + r.kind + "): " + (r.passed ? "PASSED" : "FAILED") + "\n\n";
  std::snprintf(b, sizeof b, "Scene %s; %s after %.1f s (ticks %llu to %llu).\n\n", r.scene.c_str(), r.ending.c_str(), r.time_s,
                static_cast<unsigned long long>(r.start_tick), static_cast<unsigned long long>(r.end_tick));
  s += b;
  if (!r.failures.empty()) {
    s += "Why it failed:\n\n";
    for (const auto& f : r.failures) s += "- " + f + "\n";
    s += "\n";
  }
  s += "| criterion | value | limit | |\n|---|---|---|---|\n";
  for (const auto& c : r.criteria) {
    std::snprintf(b, sizeof b, "| %s | %.4g %s | %.4g %s | %s |\n", c.name.c_str(), c.value, c.unit.c_str(), c.limit, c.unit.c_str(),
                  c.passed ? "pass" : "FAIL");
    s += b;
  }
  std::snprintf(b, sizeof b,
                "\nPath length %.3f m; peak force %.2f N, mean force in contact %.2f N, %.2f s above the force limit; largest strain at the "
                "instrument %.3f, largest edge strain %.3f; longest hold %.1f s.\n",
                r.path_length_m, r.peak_force_n, r.mean_contact_force_n, r.time_above_force_limit_s, r.max_tip_strain, r.max_edge_strain,
                r.longest_hold_s);
  s += b;
  if (r.incision_length_m) {
    std::snprintf(b, sizeof b,
                  "Incision %.1f mm long, %.1f mm deep on average (%.1f mm at most), at most %.1f mm off the line; largest strain where the "
                  "blade cut %.3f.\n",
                  1e3 * *r.incision_length_m, 1e3 * r.incision_mean_depth_m, 1e3 * r.incision_max_depth_m, 1e3 * r.incision_deviation_m,
                  r.incision_cut_strain);
    s += b;
  }
  if (r.mark_distance_m) {
    std::snprintf(b, sizeof b, "Mark %.1f mm from the target's surface.\n", 1e3 * *r.mark_distance_m);
    s += b;
  }
  return s;
}

}  // namespace viscera::training
