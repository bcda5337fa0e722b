#include "viscera/recording/resimulation_check.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <bit>
#include <cstdint>
#include <map>
#include <tuple>

#include "viscera/common/input_error.hpp"

namespace viscera::recording {

namespace proto = viscera::protocol;
using common::exact_number;

namespace {

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }
template <typename Range>
bool same_bits(const Range& a, const Range& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits(a[i], b[i])) return false;
  return true;
}

/// The first field of two forces that differs, or nullopt: (name, recorded, recomputed).
std::optional<std::tuple<std::string, std::string, std::string>> force_difference(const ExpectedForce& e, const proto::Force& f,
                                                                                  const LockstepPlan& plan) {
  const bool compare_strain = plan.strain_recorded, compare_cutting = plan.cutting_recorded;
  if (e.in_contact != f.in_contact) return std::make_tuple("in_contact", e.in_contact ? "true" : "false", f.in_contact ? "true" : "false");
  if (compare_cutting && e.cutting != f.cutting) return std::make_tuple("cutting", e.cutting ? "true" : "false", f.cutting ? "true" : "false");
  if (compare_cutting && !same_bits(e.cut_edge_strain, f.cut_edge_strain))
    return std::make_tuple("cut_edge_strain", exact_number(e.cut_edge_strain), exact_number(f.cut_edge_strain));
  const char* axes = "xyz";
  const auto vec = [&](const char* name, const proto::Vector3& a,
                       const proto::Vector3& b) -> std::optional<std::tuple<std::string, std::string, std::string>> {
    for (int k = 0; k < 3; ++k)
      if (!same_bits(a[k], b[k])) return std::make_tuple(std::string(name) + "." + axes[k], exact_number(a[k]), exact_number(b[k]));
    return std::nullopt;
  };
  if (auto d = vec("force", e.force, f.force)) return d;
  if (auto d = vec("torque", e.torque, f.torque)) return d;
  if (auto d = vec("contact_point", e.contact_point, f.contact_point)) return d;
  if (auto d = vec("contact_normal", e.contact_normal, f.contact_normal)) return d;
  if (!same_bits(e.penetration_m, f.penetration_m))
    return std::make_tuple("penetration_m", exact_number(e.penetration_m), exact_number(f.penetration_m));
  if (compare_strain && !same_bits(e.max_edge_strain, f.max_edge_strain))
    return std::make_tuple("max_edge_strain", exact_number(e.max_edge_strain), exact_number(f.max_edge_strain));
  if (plan.tip_strain_recorded && !same_bits(e.tip_strain, f.tip_strain))
    return std::make_tuple("tip_strain", exact_number(e.tip_strain), exact_number(f.tip_strain));
  if (plan.organ_epoch_recorded && e.organ_epoch != f.organ_epoch)
    return std::make_tuple("organ_epoch", std::to_string(e.organ_epoch), std::to_string(f.organ_epoch));
  return std::nullopt;
}

std::string describe(std::uint32_t instrument, std::uint64_t seq, bool stepped) {
  return "instrument " + std::to_string(instrument) + ", command " + std::to_string(seq) + (stepped ? ", stepped" : ", answered at once");
}

}  // namespace

void ResimulationCheck::diverged(Divergence d) {
  if (!first_) first_ = std::move(d);
}

void ResimulationCheck::check(const proto::LockstepResult& r) {
  ++counts_.ticks;
  if (!r.error.empty()) return diverged({r.tick, "lockstep", "the step", "error", "", r.error});
  check_forces(r);
  check_events(r);
  check_frame(r);
}

void ResimulationCheck::check_forces(const proto::LockstepResult& r) {
  std::map<std::tuple<std::uint32_t, std::uint64_t, bool>, proto::Force> got;  // instrument, seq, stepped
  std::string why;
  for (const auto& p : r.forces)
    if (const auto f = proto::decode_force(p, &why)) got[{f->instrument_id, f->command_seq, f->step_time_ns > 0}] = *f;
  const auto expected = plan_.forces.find(r.tick);
  std::size_t matched = 0;
  if (expected != plan_.forces.end())
    for (const ExpectedForce& e : expected->second) {
      ++counts_.forces_compared;
      const auto it = got.find({e.instrument_id, e.command_seq, e.stepped});
      if (it == got.end()) {
        ++counts_.forces_not_reproduced;
        diverged({r.tick, "force_feedback", describe(e.instrument_id, e.command_seq, e.stepped), "(the whole force)", "recorded", "not produced"});
        continue;
      }
      ++matched;
      if (const auto d = force_difference(e, it->second, plan_)) {
        diverged({r.tick, "force_feedback", describe(e.instrument_id, e.command_seq, e.stepped), std::get<0>(*d), std::get<1>(*d), std::get<2>(*d)});
      } else {
        ++counts_.forces_identical;
        if (!same_bits(e.stiffness, it->second.stiffness)) ++counts_.stiffness_differences;
      }
    }
  // Forces the recording does not have (a best-effort sample the recorder lost) are counted, not
  // compared: the recording's drop count says whether any were lost.
  counts_.forces_not_recorded += got.size() - matched;
}

void ResimulationCheck::check_events(const proto::LockstepResult& r) {
  std::vector<proto::Event> got;
  std::string why;
  for (const auto& p : r.events)
    if (const auto e = proto::decode_event(p, &why); e && e->kind != proto::EventKind::request_refused) got.push_back(*e);
  const auto expected = plan_.events.find(r.tick);
  const std::size_t n = expected == plan_.events.end() ? 0 : expected->second.size();
  for (std::size_t k = 0; k < std::max(n, got.size()); ++k) {
    if (k >= n) {
      diverged({r.tick, "event", std::string(proto::event_name(got[k].kind)), "(the whole event)", "not recorded", "raised"});
      continue;
    }
    const ExpectedEvent& e = expected->second[k];
    ++counts_.events_compared;
    if (k >= got.size()) {
      diverged({r.tick, "event", std::string(proto::event_name(e.kind)), "(the whole event)", "recorded", "not raised"});
      continue;
    }
    const proto::Event& g = got[k];
    const std::string what = std::string(proto::event_name(e.kind)) + " (event " + std::to_string(k + 1) + " of the tick)";
    if (e.kind != g.kind)
      diverged({r.tick, "event", what, "kind", proto::event_name(e.kind), proto::event_name(g.kind)});
    else if (e.instrument_id != g.instrument_id || e.client_id != g.client_id)
      diverged({r.tick, "event", what, "instrument_id/client_id", std::to_string(e.instrument_id) + "/" + std::to_string(e.client_id),
                std::to_string(g.instrument_id) + "/" + std::to_string(g.client_id)});
    else if (e.request_seq != g.request_seq)
      diverged({r.tick, "event", what, "request_seq", std::to_string(e.request_seq), std::to_string(g.request_seq)});
    else if (!same_bits(e.sim_time_s, g.sim_time_s))
      diverged({r.tick, "event", what, "sim_time_s", exact_number(e.sim_time_s), exact_number(g.sim_time_s)});
    else
      ++counts_.events_identical;
  }
}

void ResimulationCheck::check_frame(const proto::LockstepResult& r) {
  const auto expected = plan_.frames.find(r.tick);
  if (expected == plan_.frames.end()) return;
  ++counts_.frames_compared;
  std::string why;
  const auto f = r.frame.empty() ? std::nullopt : proto::decode_mesh_frame(r.frame, &why);
  if (!f) return diverged({r.tick, "mesh_frame", "the surface", "(the whole frame)", "recorded", "not produced"});
  const ExpectedFrame& e = expected->second;
  if (!same_bits(e.sim_time_s, f->sim_time_s))
    return diverged({r.tick, "mesh_frame", "the surface", "sim_time_s", exact_number(e.sim_time_s), exact_number(f->sim_time_s)});
  if (f->topology_generation != e.topology_generation)
    return diverged({r.tick, "mesh_frame", "the surface", "topology generation (cuts)", std::to_string(e.topology_generation),
                     std::to_string(f->topology_generation)});
  if (f->positions.size() != 3 * e.vertex_count)
    return diverged({r.tick, "mesh_frame", "the surface", "vertex count", std::to_string(e.vertex_count), std::to_string(f->positions.size() / 3)});
  if (fnv1a(f->positions.data(), f->positions.size() * sizeof(float)) == e.digest) {
    ++counts_.frames_identical;
    return;
  }
  if (first_) return;  // only the first divergence is named
  // Name the first vertex that differs: the recorded frame, read again.
  Divergence d{r.tick, "mesh_frame", "the surface", "positions", "", ""};
  recording_.for_each(
      [&](const RecordedChannel& ch, const mcap::Message& m) {
        if (ch.stream != proto::Stream::mesh_frame) return true;
        const auto rec = proto::decode_mesh_frame(m.data, &why);
        if (!rec || rec->tick != r.tick) return true;
        for (std::size_t i = 0; i < rec->positions.size() && i < f->positions.size(); ++i)
          if (!same_bits(rec->positions[i], f->positions[i])) {
            d.field = "positions[vertex " + std::to_string(i / 3) + "]." + "xyz"[i % 3];
            d.recorded = exact_number(rec->positions[i]);
            d.recomputed = exact_number(f->positions[i]);
            break;
          }
        return false;
      },
      e.log_time_ns, e.log_time_ns);
  diverged(std::move(d));
}

bool ResimulationCheck::identical() const {
  return !first_ && counts_.forces_identical == plan_.recorded_forces && counts_.events_identical == plan_.recorded_events &&
         counts_.frames_identical == plan_.recorded_frames;
}

nlohmann::json ResimulationCheck::report() const {
  nlohmann::json j;
  j["identical"] = identical();
  j["ticks"] = {{"first", plan_.first_tick}, {"last", plan_.last_tick}, {"run", counts_.ticks}};
  j["forces"] = {{"recorded", plan_.recorded_forces},
                 {"compared", counts_.forces_compared},
                 {"identical", counts_.forces_identical},
                 {"not_reproduced", counts_.forces_not_reproduced},
                 {"not_in_recording", counts_.forces_not_recorded},
                 {"stiffness_differences", counts_.stiffness_differences}};
  j["events"] = {{"recorded", plan_.recorded_events}, {"compared", counts_.events_compared}, {"identical", counts_.events_identical}};
  j["frames"] = {{"recorded", plan_.recorded_frames}, {"compared", counts_.frames_compared}, {"identical", counts_.frames_identical}};
  if (first_)
    j["first_divergence"] = {{"tick", first_->tick},   {"topic", first_->topic},       {"message", first_->what},
                             {"field", first_->field}, {"recorded", first_->recorded}, {"recomputed", first_->recomputed}};
  else
    j["first_divergence"] = nullptr;
  j["notes"] = plan_.notes;
  return j;
}

}  // namespace viscera::recording
