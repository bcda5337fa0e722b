#include "viscera/recording/lockstep_plan.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <tuple>

#include <nlohmann/json.hpp>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/protocol/request_json.hpp"

namespace viscera::recording {

namespace proto = viscera::protocol;
using common::InputError;

std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t h) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

proto::LockstepStep LockstepPlan::step(std::uint64_t tick) const {
  if (const auto it = steps.find(tick); it != steps.end()) return it->second;
  proto::LockstepStep s;
  s.tick = tick;
  return s;
}

namespace {

// A client that runs twice with the same id numbers its commands and requests from 1 again, so
// a command is named by its client stamp too (a force echoes it), and a request by when it came.
using CommandKey = std::tuple<std::uint32_t, std::uint32_t, std::uint64_t, std::int64_t>;  // client, instrument, seq, client stamp
using RequestKey = std::pair<std::uint32_t, std::uint64_t>;  // client, request_seq
struct TimedPayload {
  std::uint64_t log_time;
  std::vector<std::uint8_t> payload;
};

struct Stepped {
  std::uint32_t client;
  std::uint64_t seq;
  std::uint64_t tick;
};

proto::SessionRequest request(std::uint32_t client, proto::Action action, std::uint32_t instrument = 0) {
  proto::SessionRequest r;
  r.client_id = client;
  r.action = action;
  r.instrument_id = instrument;
  return r;
}

/// Builds a plan in four phases, each a member: the recording read once, the scene's own account of
/// the requests before the recorder joined, the events, and the forces.
class PlanBuilder {
 public:
  explicit PlanBuilder(Recording& recording) : recording_(recording) {}

  LockstepPlan build() {
    start_from_first_scene();
    read_messages();
    add_changes_before_recording();
    add_events();
    add_forces();
    note_late_join();
    return std::move(plan_);
  }

 private:
  void start_from_first_scene() {
    const auto& scenes = recording_.scenes();
    if (scenes.empty())
      throw InputError(recording_.path(), 0, "viscera.scene", "missing: the recording holds no scene files (was the server older than schema 7?)");
    plan_.scene =
        *std::min_element(scenes.begin(), scenes.end(), [](const RecordedScene& a, const RecordedScene& b) { return a.log_time_ns < b.log_time_ns; });
    plan_.first_tick = plan_.scene.first_tick;
    plan_.sim_time_s = plan_.scene.sim_time_s;
    plan_.last_tick = plan_.first_tick;
    const auto& info = recording_.info();
    const auto it = info.find("schema_version");
    const std::string version = it == info.end() ? "" : it->second;
    const int schema =
        !version.empty() && version.size() <= 3 && std::all_of(version.begin(), version.end(), [](char c) { return c >= '0' && c <= '9'; })
            ? std::stoi(version)
            : proto::kSchemaVersion;
    if (schema < 8) {
      plan_.strain_recorded = false;
      plan_.notes.push_back("recorded with protocol schema " + version + ": its forces carry no edge strain, which is not compared");
    }
    if (schema < 17) {
      plan_.cutting_recorded = false;
      plan_.notes.push_back("recorded with protocol schema " + version +
                            ": its forces do not say whether a blade cut, nor the strain where it cut, which are not compared");
    }
    if (schema < 18) {
      plan_.tip_strain_recorded = false;
      plan_.notes.push_back("recorded with protocol schema " + version + ": its forces carry no strain at the instrument, which is not compared");
    }
    if (schema < 19) {
      plan_.organ_epoch_recorded = false;
      plan_.notes.push_back("recorded with protocol schema " + version +
                            ": its forces do not count the organ's resets and loads, which is not compared");
    }
  }

  /// The whole recording once: commands and requests by their keys, server events and forces in
  /// recorded order, and the frames straight into the plan.
  void read_messages() {
    std::uint64_t undecodable = 0;
    std::string why;
    recording_.for_each([&](const RecordedChannel& ch, const mcap::Message& m) {
      bool read = true;
      switch (ch.stream) {
        case proto::Stream::instrument_command:
          if (const auto c = proto::decode_command(m.data, &why))
            commands_[{c->client_id, c->instrument_id, c->seq, c->client_stamp_ns}] = m.data;
          else
            read = false;
          break;
        case proto::Stream::session_request:
          if (const auto r = proto::decode_session_request(m.data, &why))
            requests_[{r->client_id, r->request_seq}].push_back({m.log_time, m.data});
          else
            read = false;
          break;
        case proto::Stream::force_feedback:
          if (const auto f = proto::decode_force(m.data, &why)) {
            if (f->tick == 0) {
              ++untimed_;
            } else if (f->tick >= plan_.first_tick) {
              forces_.push_back(*f);
              force_log_times_.push_back(m.log_time);
            }
          } else {
            read = false;
          }
          break;
        case proto::Stream::event:
          if (const auto e = proto::decode_event(m.data, &why)) {
            if (e->source_client_id == 0 && e->tick >= plan_.first_tick) {
              events_.push_back(*e);
              event_log_times_.push_back(m.log_time);
            }
          } else {
            read = false;
          }
          break;
        case proto::Stream::mesh_frame:
          if (const auto f = proto::decode_mesh_frame(m.data, &why))
            add_frame(*f, m.log_time);
          else
            read = false;
          break;
        default: break;
      }
      if (!read) ++undecodable;
      return true;
    });
    if (forces_.empty() && plan_.frames.empty() && events_.empty() && untimed_ > 0)
      throw InputError(recording_.path(), 0, "force_feedback",
                       "no message carries a tick: recorded from a server older than schema 7, it cannot be re-simulated");
    if (undecodable > 0) plan_.notes.push_back(std::to_string(undecodable) + " recorded messages did not verify and were left out");
  }

  void add_frame(const proto::MeshFrame& f, std::uint64_t log_time) {
    if (f.tick == 0) {
      ++untimed_;
      return;
    }
    if (f.tick < plan_.first_tick) return;
    plan_.frames[f.tick] = {f.sim_time_s, fnv1a(f.positions.data(), f.positions.size() * sizeof(float)), f.positions.size() / 3, log_time,
                            f.topology_generation};
    step_at(f.tick).want_frame = true;
    plan_.last_tick = std::max(plan_.last_tick, f.tick);
    ++plan_.recorded_frames;
  }

  proto::LockstepStep& step_at(std::uint64_t tick) {
    auto& s = plan_.steps.try_emplace(tick).first->second;
    s.tick = tick;
    return s;
  }

  /// Requests that took effect before the recorder joined, from the scene's own account.
  void add_changes_before_recording() {
    if (plan_.scene.settings_json.empty()) return;
    std::string why;
    try {
      const auto settings = common::parse_json(plan_.scene.settings_json, "the scene's settings");
      for (const auto& change : settings.value("changes", nlohmann::json::array())) {
        const std::uint64_t tick = change.value("tick", std::uint64_t{0});
        if (tick < plan_.first_tick) continue;
        if (const auto r = proto::session_request_from_json(change, &why))
          step_at(tick).requests.push_back(proto::encode(*r));
        else
          plan_.notes.push_back("a change of the scene before the recording began does not read (" + why + "): left out");
      }
    } catch (const std::exception& e) {  // an InputError of the parse, or a field of the wrong type
      plan_.notes.push_back(std::string("the scene's settings do not read: ") + e.what());
    }
  }

  /// Events: the requests they show taking effect, and what each tick must raise.
  void add_events() {
    for (std::size_t i = 0; i < events_.size(); ++i) {
      const proto::Event& e = events_[i];
      plan_.last_tick = std::max(plan_.last_tick, e.tick);
      if (e.kind != proto::EventKind::request_refused) {
        plan_.events[e.tick].push_back({e.kind, e.instrument_id, e.client_id, e.request_seq, e.sim_time_s});
        ++plan_.recorded_events;
      }
      auto& requests = step_at(e.tick).requests;
      switch (e.kind) {
        case proto::EventKind::instrument_claimed:
          requests.push_back(proto::encode(request(e.client_id, proto::Action::claim_instrument, e.instrument_id)));
          claimed_at_[e.instrument_id] = e.tick;
          break;
        case proto::EventKind::instrument_released:
          // By its owner or by the lease (no lease runs in lockstep: the owner releases it); a scene
          // replaced releases every instrument by itself. Recordings older than schema 12 say so
          // only in the text.
          if (e.reason != proto::EventReason::scene_replaced &&
              !(e.reason == proto::EventReason::unspecified && e.text.find("scene was replaced") != std::string::npos))
            requests.push_back(proto::encode(request(e.client_id, proto::Action::release_instrument, e.instrument_id)));
          break;
        case proto::EventKind::paused: requests.push_back(proto::encode(request(e.client_id, proto::Action::pause))); break;
        case proto::EventKind::resumed: requests.push_back(proto::encode(request(e.client_id, proto::Action::resume))); break;
        case proto::EventKind::organ_reset: requests.push_back(proto::encode(request(e.client_id, proto::Action::reset))); break;
        case proto::EventKind::scene_loaded:
        case proto::EventKind::material_changed:
        case proto::EventKind::physics_rate_changed:
          if (const auto* payload = named_request(e, event_log_times_[i])) requests.push_back(*payload);
          break;
        default: break;  // raised by the physics itself
      }
    }
  }

  /// The recorded request an event names: the newest of that number that came before the event
  /// (the first if none did); null, with a note, when the recording lacks it.
  const std::vector<std::uint8_t>* named_request(const proto::Event& e, std::uint64_t event_log_time) {
    const auto it = requests_.find({e.client_id, e.request_seq});
    if (it == requests_.end()) {
      plan_.notes.push_back(std::string("tick ") + std::to_string(e.tick) + ": " + proto::event_name(e.kind) + " by client " +
                            std::to_string(e.client_id) + " names request " + std::to_string(e.request_seq) +
                            ", which is not in the recording: it is not re-run");
      return nullptr;
    }
    const auto& candidates = it->second;
    auto chosen = candidates.begin();
    for (auto c = candidates.begin(); c != candidates.end() && c->log_time <= event_log_time; ++c) chosen = c;
    return &chosen->payload;
  }

  /// Forces: the commands stepped and the commands answered, and what each result must hold.
  void add_forces() {
    std::map<std::uint32_t, Stepped> last_stepped;  // per instrument
    for (std::size_t i = 0; i < forces_.size(); ++i) {
      const proto::Force& f = forces_[i];
      const bool stepped = f.step_time_ns > 0;
      const std::uint64_t result_tick = stepped ? f.tick : f.tick + 1;
      plan_.forces[result_tick].push_back({f.instrument_id, f.client_id, f.command_seq, stepped, f.in_contact, f.force, f.torque, f.contact_point,
                                           f.contact_normal, f.penetration_m, f.max_edge_strain, f.stiffness, force_log_times_[i], f.cutting,
                                           f.cut_edge_strain, f.tip_strain, f.organ_epoch});
      ++plan_.recorded_forces;
      plan_.last_tick = std::max(plan_.last_tick, result_tick);
      if (stepped) {
        const auto prev = last_stepped.find(f.instrument_id);
        const auto claim = claimed_at_.find(f.instrument_id);
        const bool claimed_now = claim != claimed_at_.end() && claim->second == f.tick;
        const bool same = prev != last_stepped.end() && prev->second.client == f.client_id && prev->second.seq == f.command_seq &&
                          prev->second.tick + 1 == f.tick && !claimed_now;
        if (!same)
          if (const auto* c = command_of(f)) step_at(f.tick).commands.push_back(*c);
        last_stepped[f.instrument_id] = {f.client_id, f.command_seq, f.tick};
      } else if (const auto* c = command_of(f)) {
        step_at(result_tick).answers.push_back(*c);
      }
    }
    if (missing_commands_ > 5) plan_.notes.push_back(std::to_string(missing_commands_) + " commands in all are missing from the recording");
    if (untimed_ > 0) plan_.notes.push_back(std::to_string(untimed_) + " messages carry no tick (an older server's) and are not compared");
  }

  /// The recorded command a force names; null, with a note for the first five, when it is missing.
  const std::vector<std::uint8_t>* command_of(const proto::Force& f) {
    const auto it = commands_.find({f.client_id, f.instrument_id, f.command_seq, f.command_client_stamp_ns});
    if (it != commands_.end()) return &it->second;
    if (++missing_commands_ <= 5)
      plan_.notes.push_back("tick " + std::to_string(f.tick) + ": command " + std::to_string(f.command_seq) + " of client " +
                            std::to_string(f.client_id) + " (instrument " + std::to_string(f.instrument_id) +
                            ") is not in the recording: it cannot be given again");
    return nullptr;
  }

  /// Surface frames come from the scene's start at 30-60 Hz: a first one much later means the
  /// recorder joined late, and what happened before it is not in the recording.
  void note_late_join() {
    if (plan_.frames.empty() || plan_.frames.begin()->first <= plan_.first_tick + 200) return;
    const std::uint64_t first = plan_.frames.begin()->first;
    plan_.notes.push_back("the recording joined the scene at about tick " + std::to_string(first) + ", " + std::to_string(first - plan_.first_tick) +
                          " ticks after it was loaded: those ticks are re-run with no input, which reproduces them only if nothing touched "
                          "the organ before");
  }

  Recording& recording_;
  LockstepPlan plan_;
  std::map<CommandKey, std::vector<std::uint8_t>> commands_;
  std::map<RequestKey, std::vector<TimedPayload>> requests_;  // in log-time order
  std::vector<proto::Event> events_;  // server events, in recorded order
  std::vector<std::uint64_t> event_log_times_;  // parallel to events_
  std::vector<proto::Force> forces_;  // in recorded order
  std::vector<std::uint64_t> force_log_times_;  // parallel to forces_
  std::map<std::uint32_t, std::uint64_t> claimed_at_;  // instrument -> tick of its last claim
  std::uint64_t untimed_ = 0, missing_commands_ = 0;
};

}  // namespace

LockstepPlan make_lockstep_plan(Recording& recording) { return PlanBuilder(recording).build(); }

}  // namespace viscera::recording
