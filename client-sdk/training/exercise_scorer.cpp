#include "viscera/training/exercise_scorer.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace viscera::training {

namespace proto = viscera::protocol;

namespace {

double norm(const proto::Vector3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
double distance(const proto::Vector3& a, const proto::Vector3& b) { return norm({a[0] - b[0], a[1] - b[1], a[2] - b[2]}); }

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char s[200];
  std::snprintf(s, sizeof s, fmt, a, b, c);
  return s;
}

/// From a point to a region's surface (0 inside it) [m].
double distance_to_region(const proto::Vector3& p, const proto::RegionInfo& r) {
  if (r.shape == proto::RegionShape::sphere) return std::max(0.0, distance(p, r.center) - r.radius_m);
  // A box, or a tagged element set by its bounding box (the trainer has no mesh; docs/TRAINING.md).
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({r.box_min[a] - p[a], 0.0, p[a] - r.box_max[a]});
    d2 += d * d;
  }
  return std::sqrt(d2);
}

}  // namespace

ExerciseScorer::ExerciseScorer(Exercise exercise) : exercise_(std::move(exercise)) {
  r_.exercise = exercise_.name;
  r_.kind = kind_name(exercise_.kind);
  r_.scene = exercise_.scene;
  r_.source = exercise_.source;
}

void ExerciseScorer::take(proto::Stream stream, std::span<const std::uint8_t> payload) {
  std::string why;
  switch (stream) {
    case proto::Stream::instrument_command:
      if (const auto c = proto::decode_command(payload, &why)) {
        if (c->instrument_id != exercise_.instrument) return;
        commands_[{c->instrument_id, c->client_id, c->seq}] = *c;
      } else {
        ++undecodable_;
      }
      return;
    case proto::Stream::force_feedback:
      if (const auto f = proto::decode_force(payload, &why)) {
        if (f->instrument_id != exercise_.instrument || f->tick == 0) return;
        newest_tick_ = std::max(newest_tick_, f->tick);
        // Its command is looked up when it is processed: a recorder or a tap may take the force
        // stream before the command stream of the same moment.
        pending_.push_back({f->tick, 1, arrivals_++, *f, std::nullopt});
      } else {
        ++undecodable_;
      }
      return;
    case proto::Stream::event:
      if (const auto e = proto::decode_event(payload, &why)) {
        if (e->source_client_id != 0 || e->tick == 0) return;  // annotations (the trainer's own feedback among them)
        newest_tick_ = std::max(newest_tick_, e->tick);
        pending_.push_back({e->tick, 0, arrivals_++, std::nullopt, *e});
      } else {
        ++undecodable_;
      }
      return;
    case proto::Stream::scene_state:
      if (const auto s = proto::decode_scene(payload, &why)) {
        if (s->name != exercise_.scene) return;
        rate_hz_ = s->physics_rate_hz;
        top_ = proto::Vector3{0.5 * (s->bounds_min[0] + s->bounds_max[0]), 0.5 * (s->bounds_min[1] + s->bounds_max[1]), s->bounds_max[2]};
        for (const auto& g : s->regions)
          if (g.name == exercise_.target_region) target_ = g;
      } else {
        ++undecodable_;
      }
      return;
    default: return;
  }
}

void ExerciseScorer::advance(std::uint64_t tick) {
  std::stable_sort(pending_.begin(), pending_.end());
  std::size_t k = 0;
  for (; k < pending_.size() && pending_[k].tick <= tick; ++k) process(pending_[k]);
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(k));
  // Commands far behind what was processed are answered long ago (a force echoes the newest
  // command of its tick): keep the last 10,000 per client.
  if (commands_.size() > 50000)
    for (auto it = commands_.begin(); it != commands_.end();) {
      const auto group_end = commands_.upper_bound({std::get<0>(it->first), std::get<1>(it->first), ~std::uint64_t{0}});
      const std::uint64_t newest = std::get<2>(std::prev(group_end)->first);
      while (it != group_end && std::get<2>(it->first) + 10000 < newest) it = commands_.erase(it);
      it = group_end;
    }
}

void ExerciseScorer::finish(const std::string& why) {
  advance(~std::uint64_t{0});
  if (started() && !ended_) end(last_tick_, false, why);
}

std::vector<std::string> ExerciseScorer::take_feedback() { return std::exchange(feedback_, {}); }

void ExerciseScorer::say(std::string line) { feedback_.push_back(std::move(line)); }

double ExerciseScorer::seconds(std::uint64_t from_tick, std::uint64_t to_tick) const {
  return rate_hz_ > 0 ? static_cast<double>(to_tick - from_tick) / rate_hz_ : 0.0;
}

void ExerciseScorer::process(const Pending& p) {
  if (ended_) return;
  if (start_tick_ && rate_hz_ > 0 && seconds(*start_tick_, p.tick) > exercise_.time_limit_s) {
    end(*start_tick_ + static_cast<std::uint64_t>(std::llround(exercise_.time_limit_s * rate_hz_)), false, "out of time");
    return;
  }
  if (p.event) process_event(*p.event);
  if (p.force && start_tick_) {
    const auto it = commands_.find({p.force->instrument_id, p.force->client_id, p.force->command_seq});
    process_force(*p.force, it != commands_.end() ? std::optional<proto::Command>(it->second) : std::nullopt);
  }
}

void ExerciseScorer::process_event(const proto::Event& e) {
  // The scene's name is a field since schema 12; older recordings say it only in the text.
  const bool this_scene = e.scene.empty() ? e.text.rfind("loaded scene " + exercise_.scene + " (", 0) == 0 : e.scene == exercise_.scene;
  if (e.kind == proto::EventKind::scene_loaded && !start_tick_ && this_scene) {
    start_tick_ = e.tick;
    last_tick_ = e.tick;
    r_.started = true;
    r_.start_tick = e.tick;
    say("exercise " + exercise_.name + " started: " + exercise_.description);
    return;
  }
  if (!start_tick_ || exercise_.kind != ExerciseKind::retraction || e.instrument_id != exercise_.instrument) return;
  if (e.kind == proto::EventKind::grasped) {
    grasped_ = true;
    grasp_z_ = last_tip_ ? std::optional<double>((*last_tip_)[2]) : std::nullopt;
    say(format("grasped at %.1f s: lift by %.0f mm and hold", seconds(*start_tick_, e.tick), 1e3 * exercise_.lift_m));
  } else if (e.kind == proto::EventKind::let_go && grasped_) {
    grasped_ = false;
    hold_start_.reset();
    ++r_.drops;
    say(format("dropped at %.1f s, before the hold of %.0f s was complete", seconds(*start_tick_, e.tick), exercise_.hold_s));
  }
}

void ExerciseScorer::process_force(const proto::Force& f, const std::optional<proto::Command>& c) {
  const bool has_tip = c.has_value();
  if (!has_tip) ++r_.samples_without_command;
  const double F = norm(f.force);
  ++r_.samples;
  r_.peak_force_n = std::max(r_.peak_force_n, F);
  r_.max_edge_strain = std::max(r_.max_edge_strain, f.max_edge_strain);
  r_.max_tip_strain = std::max(r_.max_tip_strain, f.tip_strain);
  tip_strain_samples_ += f.in_contact && f.tip_strain > 0;
  r_.incision_cut_strain = std::max(r_.incision_cut_strain, f.cut_edge_strain);
  if (f.in_contact) {
    contact_force_sum_ += F;
    ++contact_samples_;
    if (!in_contact_) touch_z_ = f.contact_point[2];  // where this contact began
  }
  in_contact_ = f.in_contact;
  if (F > exercise_.peak_force_limit_n) {
    if (f.tick != last_above_tick_) r_.time_above_force_limit_s += seconds(0, 1);
    last_above_tick_ = f.tick;
    if (!warned_force_) say(format("force %.2f N above the safe limit of %.2f N", F, exercise_.peak_force_limit_n));
    warned_force_ = true;
  }
  if (exercise_.edge_strain_limit && f.max_edge_strain > *exercise_.edge_strain_limit && !warned_strain_) {
    say(format("largest edge strain %.2f above the safe limit of %.2f", f.max_edge_strain, *exercise_.edge_strain_limit));
    warned_strain_ = true;
  }
  if (exercise_.tip_strain_limit && f.tip_strain > *exercise_.tip_strain_limit && !warned_tip_strain_) {
    say(format("tissue strain at the instrument %.2f above the safe limit of %.2f", f.tip_strain, *exercise_.tip_strain_limit));
    warned_tip_strain_ = true;
  }
  if (has_tip) walk_commands(*c, f);
  if (ended_) return;
  last_tick_ = f.tick;
  const double t = seconds(*start_tick_, f.tick);

  // The task's own progress.
  bool holding = false;
  switch (exercise_.kind) {
    case ExerciseKind::palpation:
    case ExerciseKind::incision: break;
    case ExerciseKind::force_drill: holding = std::abs(F - exercise_.target_force_n) <= exercise_.force_tolerance_n; break;
    case ExerciseKind::retraction:
      if (grasped_ && last_tip_) {
        if (!grasp_z_) grasp_z_ = (*last_tip_)[2];
        holding = std::abs((*last_tip_)[2] - *grasp_z_ - exercise_.lift_m) <= exercise_.lift_tolerance_m;
      }
      break;
  }
  if (exercise_.kind == ExerciseKind::palpation || exercise_.kind == ExerciseKind::incision) return;
  if (!holding) {
    hold_start_.reset();
    announced_hold_s_ = 0;
    return;
  }
  if (!hold_start_) hold_start_ = f.tick;
  const double held = seconds(*hold_start_, f.tick);
  r_.longest_hold_s = std::max(r_.longest_hold_s, held);
  if (held >= announced_hold_s_ + 1.0) {
    announced_hold_s_ = std::floor(held);
    say(format("holding: %.0f s of %.0f s", announced_hold_s_, exercise_.hold_s));
  }
  if (held >= exercise_.hold_s) end(f.tick, true, format("held for %.1f s at %.1f s", held, t));
}

void ExerciseScorer::walk_commands(const proto::Command& c, const proto::Force& f) {
  const std::uint32_t inst = c.instrument_id, client = c.client_id;
  auto it = commands_.find({inst, client, c.seq});
  if (walked_ && walked_->first == client) {
    if (c.seq <= walked_->second) return;  // walked already
    it = commands_.upper_bound({inst, client, walked_->second});
  }
  std::uint32_t buttons = 0;
  if (walked_ && walked_->first == client)
    if (const auto w = commands_.find({inst, client, walked_->second}); w != commands_.end()) buttons = w->second.buttons;
  for (; it != commands_.end() && std::get<0>(it->first) == inst && std::get<1>(it->first) == client && std::get<2>(it->first) <= c.seq; ++it) {
    const proto::Command& k = it->second;
    if (last_tip_ && walked_ && walked_->first == client) r_.path_length_m += distance(k.tip_position, *last_tip_);
    last_tip_ = k.tip_position;
    walked_ = {client, k.seq};
    const bool pressed = (k.buttons & kMarkButton) && !(buttons & kMarkButton);
    buttons = k.buttons;
    if (exercise_.kind == ExerciseKind::incision) {
      walk_incision(k, f);
      if (ended_) return;
      continue;
    }
    if (pressed && exercise_.kind == ExerciseKind::palpation) {
      // The place marked is where the tool touches the tissue (the contact point of the force
      // being processed, a few milliseconds after the press at most), not the tip's centre,
      // which lies a tip radius above it; the tip if it touches nothing.
      const proto::Vector3 mark = f.in_contact ? f.contact_point : k.tip_position;
      r_.mark_m = mark;
      if (target_) {
        r_.target_m = target_->center;
        r_.mark_distance_m = distance_to_region(mark, *target_);
      }
      say(format("marked at (%.3f, %.3f, %.3f) m", mark[0], mark[1], mark[2]) + (f.in_contact ? " on the tissue" : " (touching nothing)"));
      end(f.tick, true, "marked");
      return;
    }
  }
}

void ExerciseScorer::walk_incision(const proto::Command& k, const proto::Force& f) {
  const std::uint64_t tick = f.tick;
  // The cut button held, or the blade pressed through above the scene's cut force (schema 17).
  const bool held = (k.buttons & kMarkButton) != 0 || f.cutting;
  if (held && !cutting_) {
    cutting_ = true;
    // The surface is where the blade's last contact before cutting began (the tissue pressed
    // since has moved down with it), or the top of the organ's box if it touched nothing.
    if (!surface_z_) surface_z_ = touch_z_ ? touch_z_ : top_ ? std::optional<double>((*top_)[2]) : std::nullopt;
    say(format("cutting at %.1f s", seconds(*start_tick_, tick)));
  }
  if (!held) {
    if (cutting_ && cut_samples_ > 0) end(tick, true, "incision made");
    cutting_ = false;
    return;
  }
  if (!surface_z_ || !top_) return;
  const double depth = *surface_z_ - k.tip_position[2];
  if (depth <= 0) return;  // the blade's tip above the surface: not cutting yet
  // The line in the horizontal plane: the tip's place along it and its distance across it.
  const double ax = (*top_)[0] + exercise_.incision_from[0], ay = (*top_)[1] + exercise_.incision_from[1];
  const double dx = exercise_.incision_to[0] - exercise_.incision_from[0], dy = exercise_.incision_to[1] - exercise_.incision_from[1];
  const double length = std::hypot(dx, dy), ux = dx / length, uy = dy / length;
  const double px = k.tip_position[0] - ax, py = k.tip_position[1] - ay;
  const double along = px * ux + py * uy, across = std::abs(px * uy - py * ux);
  along_min_ = cut_samples_ == 0 ? along : std::min(along_min_, along);
  along_max_ = cut_samples_ == 0 ? along : std::max(along_max_, along);
  ++cut_samples_;
  depth_sum_ += depth;
  r_.incision_length_m = along_max_ - along_min_;
  r_.incision_deviation_m = std::max(r_.incision_deviation_m, across);
  r_.incision_max_depth_m = std::max(r_.incision_max_depth_m, depth);
  r_.incision_mean_depth_m = depth_sum_ / static_cast<double>(cut_samples_);
}

void ExerciseScorer::end(std::uint64_t tick, bool completed, const std::string& how) {
  ended_ = true;
  r_.completed = completed;
  r_.ending = how;
  r_.end_tick = tick;
  r_.time_s = start_tick_ ? seconds(*start_tick_, tick) : 0.0;
  say(std::string(completed ? "completed" : "ended") + ": " + how + format(" (%.1f s)", r_.time_s));
}

ScoreReport ExerciseScorer::report() const {
  ScoreReport r = r_;
  r.undecodable = undecodable_;
  r.mean_contact_force_n = contact_samples_ ? contact_force_sum_ / static_cast<double>(contact_samples_) : 0.0;
  if (!r.started) {
    r.ending = "never started: no loading of scene " + exercise_.scene + " was seen";
    r.failures.push_back(r.ending);
    return r;
  }
  const auto add = [&](std::string name, double value, double limit, std::string unit, bool passed, std::string why) {
    r.criteria.push_back({std::move(name), value, limit, std::move(unit), passed, passed ? "" : why});
    if (!passed) r.failures.push_back(std::move(why));
  };
  // The most telling reason first: the task's own, then safety, then time.
  if (exercise_.kind == ExerciseKind::palpation) {
    if (!r.mark_m)
      add("mark", 0, 0, "", false, "no place was marked");
    else if (!r.mark_distance_m)
      add("mark accuracy", 0, exercise_.mark_tolerance_m, "m", false, "the target region '" + exercise_.target_region + "' is not in the scene");
    else
      add("mark accuracy", *r.mark_distance_m, exercise_.mark_tolerance_m, "m", *r.mark_distance_m <= exercise_.mark_tolerance_m,
          format("the wrong place was marked: %.1f mm from the nodule (at most %.1f mm)", 1e3 * *r.mark_distance_m,
                 1e3 * exercise_.mark_tolerance_m));
  }
  if (exercise_.kind == ExerciseKind::incision) {
    const double target = std::hypot(exercise_.incision_to[0] - exercise_.incision_from[0], exercise_.incision_to[1] - exercise_.incision_from[1]);
    if (!r.incision_length_m) {
      add("incision", 0, 0, "", false, "no incision was made (the scalpel's cut button held with its tip below the surface)");
    } else {
      const double dl = std::abs(*r.incision_length_m - target), dd = std::abs(r.incision_mean_depth_m - exercise_.incision_depth_m);
      add("line", r.incision_deviation_m, exercise_.line_tolerance_m, "m", r.incision_deviation_m <= exercise_.line_tolerance_m,
          format("off the line: %.1f mm at the most (at most %.1f mm)", 1e3 * r.incision_deviation_m, 1e3 * exercise_.line_tolerance_m));
      add("depth error", dd, exercise_.depth_tolerance_m, "m", dd <= exercise_.depth_tolerance_m,
          format("%.1f mm deep on average, %.1f mm asked", 1e3 * r.incision_mean_depth_m, 1e3 * exercise_.incision_depth_m) +
              format(" (within %.1f mm)", 1e3 * exercise_.depth_tolerance_m));
      add("length error", dl, exercise_.length_tolerance_m, "m", dl <= exercise_.length_tolerance_m,
          format("%.1f mm long, %.1f mm asked", 1e3 * *r.incision_length_m, 1e3 * target) +
              format(" (within %.1f mm)", 1e3 * exercise_.length_tolerance_m));
      const double cut_limit = exercise_.cut_strain_limit();
      add("strain at the cut", r.incision_cut_strain, cut_limit, "", r.incision_cut_strain <= cut_limit,
          format("the tissue was torn where the blade cut: strain %.3f there (at most %.3f)", r.incision_cut_strain, cut_limit));
    }
  }
  if (exercise_.kind == ExerciseKind::retraction)
    add("drops", r.drops, 0, "", r.drops == 0, "the lobe was dropped " + std::to_string(r.drops) + " time(s) before the hold was complete");
  if (exercise_.kind == ExerciseKind::retraction || exercise_.kind == ExerciseKind::force_drill)
    add("longest hold", r.longest_hold_s, exercise_.hold_s, "s", r.longest_hold_s >= exercise_.hold_s,
        exercise_.kind == ExerciseKind::force_drill ? format("the force was held in %.2f +- %.2f N for at most %.1f s", exercise_.target_force_n,
                                                             exercise_.force_tolerance_n, r.longest_hold_s) +
                                                          format(" (%.0f s asked)", exercise_.hold_s)
                                                    : format("the lobe was held at %.0f +- %.0f mm for at most %.1f s", 1e3 * exercise_.lift_m,
                                                             1e3 * exercise_.lift_tolerance_m, r.longest_hold_s) +
                                                          format(" (%.0f s asked)", exercise_.hold_s));
  add("peak force", r.peak_force_n, exercise_.peak_force_limit_n, "N", r.peak_force_n <= exercise_.peak_force_limit_n,
      format("too much force: %.2f N at the peak (at most %.2f N); %.2f s above the limit", r.peak_force_n, exercise_.peak_force_limit_n,
             r.time_above_force_limit_s));
  if (const auto limit = exercise_.tip_strain_limit) {
    // Forces in contact that all carry 0 come from a server that does not measure it: not a pass.
    if (contact_samples_ > 0 && tip_strain_samples_ == 0)
      add("strain at the instrument", 0, *limit, "", false,
          "the strain at the instrument was not measured: no force in contact carried it (a server older than protocol schema 18)");
    else
      add("strain at the instrument", r.max_tip_strain, *limit, "", r.max_tip_strain <= *limit,
          format("the tissue was strained too far at the instrument: %.3f at the most (at most %.3f)", r.max_tip_strain, *limit));
  }
  if (const auto limit = exercise_.edge_strain_limit)
    add("largest edge strain", r.max_edge_strain, *limit, "", r.max_edge_strain <= *limit,
        format("the tissue was strained too far: largest edge strain %.3f (at most %.3f)", r.max_edge_strain, *limit));
  add("time", r.time_s, exercise_.time_limit_s, "s", r.completed && r.time_s <= exercise_.time_limit_s,
      r.completed ? format("too slow: %.1f s (at most %.0f s)", r.time_s, exercise_.time_limit_s) : "not completed: " + r.ending);
  r.passed = r.failures.empty();
  return r;
}

}  // namespace viscera::training
