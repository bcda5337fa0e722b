#include "viscera/recording/lockstep_plan.hpp"

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

}  // namespace

LockstepPlan make_lockstep_plan(Recording& recording) {
  if (recording.scenes().empty())
    throw InputError(recording.path(), 0, "viscera.scene", "missing: the recording holds no scene files (was the server older than schema 7?)");
  LockstepPlan plan;
  plan.scene = *std::min_element(recording.scenes().begin(), recording.scenes().end(),
                                 [](const RecordedScene& a, const RecordedScene& b) { return a.log_time_ns < b.log_time_ns; });
  plan.first_tick = plan.scene.first_tick;
  plan.sim_time_s = plan.scene.sim_time_s;
  plan.last_tick = plan.first_tick;
  if (const auto it = recording.info().find("schema_version"); it != recording.info().end() && it->second.size() == 1 && it->second < "8") {
    plan.strain_recorded = false;
    plan.notes.push_back("recorded with protocol schema " + it->second + ": its forces carry no edge strain, which is not compared");
  }

  std::map<CommandKey, std::vector<std::uint8_t>> commands;
  std::map<RequestKey, std::vector<TimedPayload>> requests;  // in log-time order
  std::vector<std::uint64_t> event_log_times;  // parallel to events
  std::vector<proto::Force> forces;  // in recorded order
  std::vector<proto::Event> events;  // server events, in recorded order
  std::vector<std::uint64_t> force_log_times;  // parallel to forces
  std::uint64_t untimed = 0, undecodable = 0;
  std::string why;
  recording.for_each([&](const RecordedChannel& ch, const mcap::Message& m) {
    switch (ch.stream) {
      case proto::Stream::instrument_command:
        if (const auto c = proto::decode_command(m.data, &why))
          commands[{c->client_id, c->instrument_id, c->seq, c->client_stamp_ns}] = m.data;
        else
          ++undecodable;
        break;
      case proto::Stream::session_request:
        if (const auto r = proto::decode_session_request(m.data, &why))
          requests[{r->client_id, r->request_seq}].push_back({m.log_time, m.data});
        else
          ++undecodable;
        break;
      case proto::Stream::force_feedback:
        if (const auto f = proto::decode_force(m.data, &why)) {
          if (f->tick == 0) {
            ++untimed;
          } else if (f->tick >= plan.first_tick) {
            forces.push_back(*f);
            force_log_times.push_back(m.log_time);
          }
        } else {
          ++undecodable;
        }
        break;
      case proto::Stream::event:
        if (const auto e = proto::decode_event(m.data, &why)) {
          if (e->source_client_id == 0 && e->tick >= plan.first_tick) {
            events.push_back(*e);
            event_log_times.push_back(m.log_time);
          }
        } else {
          ++undecodable;
        }
        break;
      case proto::Stream::mesh_frame:
        if (const auto f = proto::decode_mesh_frame(m.data, &why)) {
          if (f->tick == 0) {
            ++untimed;
          } else if (f->tick >= plan.first_tick) {
            plan.frames[f->tick] = {f->sim_time_s, fnv1a(f->positions.data(), f->positions.size() * sizeof(float)), f->positions.size() / 3,
                                    m.log_time};
            auto& step = plan.steps[f->tick];
            step.tick = f->tick;
            step.want_frame = true;
            plan.last_tick = std::max(plan.last_tick, f->tick);
            ++plan.recorded_frames;
          }
        } else {
          ++undecodable;
        }
        break;
      default: break;
    }
    return true;
  });
  if (forces.empty() && plan.frames.empty() && events.empty() && untimed > 0)
    throw InputError(recording.path(), 0, "force_feedback",
                     "no message carries a tick: recorded from a server older than schema 7, it cannot be re-simulated");
  if (undecodable > 0) plan.notes.push_back(std::to_string(undecodable) + " recorded messages did not verify and were left out");

  const auto step_at = [&](std::uint64_t tick) -> proto::LockstepStep& {
    auto& s = plan.steps.try_emplace(tick).first->second;
    s.tick = tick;
    return s;
  };

  // Requests that took effect before the recorder joined, from the scene's own account.
  if (!plan.scene.settings_json.empty()) {
    try {
      const auto settings = common::parse_json(plan.scene.settings_json, "the scene's settings");
      for (const auto& change : settings.value("changes", nlohmann::json::array())) {
        const std::uint64_t tick = change.value("tick", std::uint64_t{0});
        if (tick < plan.first_tick) continue;
        if (const auto r = proto::session_request_from_json(change, &why))
          step_at(tick).requests.push_back(proto::encode(*r));
        else
          plan.notes.push_back("a change of the scene before the recording began does not read (" + why + "): left out");
      }
    } catch (const std::exception& e) {  // an InputError of the parse, or a field of the wrong type
      plan.notes.push_back(std::string("the scene's settings do not read: ") + e.what());
    }
  }

  // Events: the requests they show taking effect, and what each tick must raise.
  std::map<std::uint32_t, std::uint64_t> claimed_at;  // instrument -> tick of its last claim
  std::uint64_t missing_requests = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const proto::Event& e = events[i];
    plan.last_tick = std::max(plan.last_tick, e.tick);
    if (e.kind != proto::EventKind::request_refused) {
      plan.events[e.tick].push_back({e.kind, e.instrument_id, e.client_id, e.request_seq, e.sim_time_s});
      ++plan.recorded_events;
    }
    auto& s = step_at(e.tick);
    switch (e.kind) {
      case proto::EventKind::instrument_claimed:
        s.requests.push_back(proto::encode(request(e.client_id, proto::Action::claim_instrument, e.instrument_id)));
        claimed_at[e.instrument_id] = e.tick;
        break;
      case proto::EventKind::instrument_released:
        // By its owner or by the lease (no lease runs in lockstep: the owner releases it); a scene
        // replaced releases every instrument by itself. Recordings older than schema 12 say so
        // only in the text.
        if (e.reason != proto::EventReason::scene_replaced &&
            !(e.reason == proto::EventReason::unspecified && e.text.find("scene was replaced") != std::string::npos))
          s.requests.push_back(proto::encode(request(e.client_id, proto::Action::release_instrument, e.instrument_id)));
        break;
      case proto::EventKind::paused: s.requests.push_back(proto::encode(request(e.client_id, proto::Action::pause))); break;
      case proto::EventKind::resumed: s.requests.push_back(proto::encode(request(e.client_id, proto::Action::resume))); break;
      case proto::EventKind::organ_reset: s.requests.push_back(proto::encode(request(e.client_id, proto::Action::reset))); break;
      case proto::EventKind::scene_loaded:
      case proto::EventKind::material_changed:
      case proto::EventKind::physics_rate_changed:
        if (const auto it = requests.find({e.client_id, e.request_seq}); it != requests.end()) {
          // The newest request of that number that came before the event (the first if none did).
          const auto& candidates = it->second;
          auto chosen = candidates.begin();
          for (auto c = candidates.begin(); c != candidates.end() && c->log_time <= event_log_times[i]; ++c) chosen = c;
          s.requests.push_back(chosen->payload);
        } else {
          ++missing_requests;
          plan.notes.push_back(std::string("tick ") + std::to_string(e.tick) + ": " + proto::event_name(e.kind) + " by client " +
                               std::to_string(e.client_id) + " names request " + std::to_string(e.request_seq) +
                               ", which is not in the recording: it is not re-run");
        }
        break;
      default: break;  // raised by the physics itself
    }
  }

  // Forces: the commands stepped and the commands answered, and what each result must hold.
  std::map<std::uint32_t, Stepped> last_stepped;  // per instrument
  std::uint64_t missing_commands = 0;
  const auto command = [&](const proto::Force& f) -> const std::vector<std::uint8_t>* {
    const auto it = commands.find({f.client_id, f.instrument_id, f.command_seq, f.command_client_stamp_ns});
    if (it != commands.end()) return &it->second;
    if (++missing_commands <= 5)
      plan.notes.push_back("tick " + std::to_string(f.tick) + ": command " + std::to_string(f.command_seq) + " of client " +
                           std::to_string(f.client_id) + " (instrument " + std::to_string(f.instrument_id) +
                           ") is not in the recording: it cannot be given again");
    return nullptr;
  };
  for (std::size_t i = 0; i < forces.size(); ++i) {
    const proto::Force& f = forces[i];
    const bool stepped = f.step_time_ns > 0;
    const std::uint64_t result_tick = stepped ? f.tick : f.tick + 1;
    plan.forces[result_tick].push_back({f.instrument_id, f.client_id, f.command_seq, stepped, f.in_contact, f.force, f.torque, f.contact_point,
                                        f.contact_normal, f.penetration_m, f.max_edge_strain, f.stiffness, force_log_times[i]});
    ++plan.recorded_forces;
    plan.last_tick = std::max(plan.last_tick, result_tick);
    if (stepped) {
      const auto prev = last_stepped.find(f.instrument_id);
      const bool claimed_now = claimed_at.count(f.instrument_id) && claimed_at[f.instrument_id] == f.tick;
      const bool same = prev != last_stepped.end() && prev->second.client == f.client_id && prev->second.seq == f.command_seq &&
                        prev->second.tick + 1 == f.tick && !claimed_now;
      if (!same)
        if (const auto* c = command(f)) step_at(f.tick).commands.push_back(*c);
      last_stepped[f.instrument_id] = {f.client_id, f.command_seq, f.tick};
    } else if (const auto* c = command(f)) {
      step_at(result_tick).answers.push_back(*c);
    }
  }
  if (missing_commands > 5) plan.notes.push_back(std::to_string(missing_commands) + " commands in all are missing from the recording");
  if (untimed > 0) plan.notes.push_back(std::to_string(untimed) + " messages carry no tick (an older server's) and are not compared");

  // Surface frames come from the scene's start at 30-60 Hz: a first one much later means the
  // recorder joined late, and what happened before it is not in the recording.
  if (!plan.frames.empty() && plan.frames.begin()->first > plan.first_tick + 200)
    plan.notes.push_back(
        "the recording joined the scene at about tick " + std::to_string(plan.frames.begin()->first) + ", " +
        std::to_string(plan.frames.begin()->first - plan.first_tick) +
        " ticks after it was loaded: those ticks are re-run with no input, which reproduces them only if nothing touched the organ before");
  return plan;
}

}  // namespace viscera::recording
