#include <cmath>  // SPDX-License-Identifier: Apache-2.0
#include <utility>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/plain_name.hpp"
#include "viscera/training/exercise.hpp"

namespace viscera::training {

using common::JsonObject;

const char* kind_name(ExerciseKind k) {
  switch (k) {
    case ExerciseKind::palpation: return "palpation";
    case ExerciseKind::retraction: return "retraction";
    case ExerciseKind::force_drill: return "force_drill";
    case ExerciseKind::incision: return "incision";
  }
  return "?";
}

namespace {

Exercise read(const nlohmann::json& j, const std::string& source) {
  const JsonObject top(j, source);
  top.require_known(
      {"name", "description", "kind", "scene", "instrument", "time_limit_s", "limits", "palpation", "retraction", "force_drill", "incision"});
  Exercise e;
  e.source = source;
  e.name = top.text("name");
  // The name names the report's files: a plain name, never a path.
  if (!common::is_plain_name(e.name))
    top.fail("name", "'" + common::printable(e.name, 80) + "' is not a plain name (" + common::kPlainNameRule + ")");
  e.description = top.text("description", "");
  const std::string kind = top.choice("kind", {"palpation", "retraction", "force_drill", "incision"}, "");
  if (kind.empty()) top.fail("kind", "missing: one of palpation, retraction, force_drill, incision");
  e.kind = kind == "palpation"    ? ExerciseKind::palpation
           : kind == "retraction" ? ExerciseKind::retraction
           : kind == "incision"   ? ExerciseKind::incision
                                  : ExerciseKind::force_drill;
  e.scene = top.text("scene");
  if (!common::is_plain_name(e.scene))
    top.fail("scene",
             "'" + common::printable(e.scene, 80) + "' is not a scene of the server's scene directory by name (" + common::kPlainNameRule + ")");
  e.instrument = static_cast<std::uint32_t>(top.integer("instrument", 1, 1'000'000, 1));
  e.time_limit_s = top.number("time_limit_s", 1, 3600, 120);
  if (top.has("limits")) {
    const JsonObject l = top.object("limits");
    l.require_known({"peak_force_n", "edge_strain", "tip_strain"});
    e.peak_force_limit_n = l.number("peak_force_n", 0.01, 100, e.peak_force_limit_n);
    // A file that sets one strain limit is scored on that one; one that sets none, on the strain
    // at the instrument.
    if (l.has("edge_strain") || l.has("tip_strain")) e.tip_strain_limit.reset();
    if (l.has("edge_strain")) e.edge_strain_limit = l.number("edge_strain", 0.001, 5, 0.5);
    if (l.has("tip_strain")) e.tip_strain_limit = l.number("tip_strain", 0.001, 5, 0.4);
  }
  // The kind's own block, and no other kind's.
  for (const char* other : {"palpation", "retraction", "force_drill", "incision"})
    if (kind != other && top.has(other)) top.fail(other, std::string("belongs to a ") + other + " exercise, not a " + kind + " one");
  if (e.kind == ExerciseKind::palpation && top.has("palpation")) {
    const JsonObject p = top.object("palpation");
    p.require_known({"region", "mark_tolerance_m"});
    e.target_region = p.text("region", e.target_region);
    e.mark_tolerance_m = p.number("mark_tolerance_m", 1e-4, 0.2, e.mark_tolerance_m);
  }
  if (e.kind == ExerciseKind::retraction && top.has("retraction")) {
    const JsonObject r = top.object("retraction");
    r.require_known({"lift_m", "tolerance_m", "hold_s"});
    e.lift_m = r.number("lift_m", 0.001, 0.2, e.lift_m);
    e.lift_tolerance_m = r.number("tolerance_m", 1e-4, 0.1, e.lift_tolerance_m);
    e.hold_s = r.number("hold_s", 0.1, 600, e.hold_s);
    if (e.lift_tolerance_m >= e.lift_m) r.fail("tolerance_m", "must be smaller than lift_m");
  }
  if (e.kind == ExerciseKind::force_drill) {
    e.hold_s = 10.0;
    if (top.has("force_drill")) {
      const JsonObject f = top.object("force_drill");
      f.require_known({"force_n", "tolerance_n", "hold_s"});
      e.target_force_n = f.number("force_n", 0.01, 50, e.target_force_n);
      e.force_tolerance_n = f.number("tolerance_n", 0.001, 10, e.force_tolerance_n);
      e.hold_s = f.number("hold_s", 0.1, 600, e.hold_s);
      if (e.force_tolerance_n >= e.target_force_n) f.fail("tolerance_n", "must be smaller than force_n");
      if (e.target_force_n + e.force_tolerance_n > e.peak_force_limit_n)
        f.fail("force_n", "the band's top exceeds limits.peak_force_n (" + std::to_string(e.peak_force_limit_n) + " N): the drill could not pass");
    }
  }
  if (e.kind == ExerciseKind::incision && top.has("incision")) {
    const JsonObject c = top.object("incision");
    c.require_known({"from_m", "to_m", "depth_m", "depth_tolerance_m", "line_tolerance_m", "length_tolerance_m"});
    for (const auto& [field, point] : {std::pair{"from_m", &e.incision_from}, std::pair{"to_m", &e.incision_to}}) {
      if (!c.has(field)) continue;
      const auto v = c.numbers(field, 2, -0.5, 0.5);
      *point = {v[0], v[1]};
    }
    e.incision_depth_m = c.number("depth_m", 0.001, 0.1, e.incision_depth_m);
    e.depth_tolerance_m = c.number("depth_tolerance_m", 1e-4, 0.05, e.depth_tolerance_m);
    e.line_tolerance_m = c.number("line_tolerance_m", 1e-4, 0.05, e.line_tolerance_m);
    e.length_tolerance_m = c.number("length_tolerance_m", 1e-4, 0.2, e.length_tolerance_m);
    if (std::hypot(e.incision_to[0] - e.incision_from[0], e.incision_to[1] - e.incision_from[1]) < 0.005)
      c.fail("to_m", "the line is shorter than 5 mm");
    if (e.depth_tolerance_m >= e.incision_depth_m) c.fail("depth_tolerance_m", "must be smaller than depth_m");
  }
  if (e.kind != ExerciseKind::incision && e.hold_s >= e.time_limit_s)
    top.fail("time_limit_s", "must leave time for the hold of " + std::to_string(e.hold_s) + " s");
  return e;
}

}  // namespace

Exercise read_exercise_file(const std::string& path) { return read(common::read_json_file(path), path); }

Exercise parse_exercise(const std::string& json_text, const std::string& source) { return read(common::parse_json(json_text, source), source); }

}  // namespace viscera::training
