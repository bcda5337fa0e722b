// Session requests the simulation server's physics thread takes between ticks: claims and  // SPDX-License-Identifier: Apache-2.0
// releases, pause, resume and reset, scenes, materials and rates built in the background, take
// over and hand back, and the lease on silent owners.
#include <chrono>
#include <cmath>

#include "viscera/common/input_error.hpp"
#include "viscera/protocol/request_json.hpp"
#include "viscera/runtime/stiffening_limit.hpp"
#include "viscera/tissue/material/material_file.hpp"

#include "simulation_server_impl.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;
using common::InputError;

/// Claim and release an instrument (its owner only); pause, resume and reset the organ, load a
/// scene, change the material or the physics rate (any client: an instructor's console or a
/// trainer).
void SimulationServer::Impl::take_sessions(const Status& status, const proto::LockstepStep* step) {
  bool changed = false;
  // `participant`: the sender (live only; a lockstep step's requests were admitted live).
  const auto take = [&](std::span<const std::uint8_t> payload, std::optional<Sender> participant) {
    std::string why;
    const auto req = proto::decode_session_request(payload, &why);
    if (!req) {
      ++counted.malformed;
      return;
    }
    // What acts on an instrument is bound to the participant that holds the client id (pause,
    // scenes and materials are any client's: DDS Security's permissions decide who may send them).
    const bool on_instrument = req->action == proto::Action::claim_instrument || req->action == proto::Action::release_instrument ||
                               req->action == proto::Action::take_over || req->action == proto::Action::hand_back;
    if (participant && on_instrument && !clients.admit(req->client_id, *participant, proto::now_ns())) {
      ++counted.other_participant;
      return;
    }
    const std::string who = "client " + std::to_string(req->client_id);
    switch (req->action) {
      case proto::Action::pause:
      case proto::Action::resume:
        if (paused != (req->action == proto::Action::pause)) {
          if (status) status(who + (paused ? " resumed" : " paused") + " the simulation");
          event(paused ? proto::EventKind::resumed : proto::EventKind::paused, 0, req->client_id);
          ++organ_epoch;  // the organ freezes or thaws under the tools
        }
        paused = req->action == proto::Action::pause;
        changed = true;
        return;
      case proto::Action::reset:
        reset_organ();
        if (status) status(who + " reset the organ to rest");
        event(proto::EventKind::organ_reset, 0, req->client_id);
        return;
      case proto::Action::load_scene:
      case proto::Action::set_material:
      case proto::Action::set_physics_rate:
        // A request concluded at once has published the state; a second copy right behind it
        // could supersede it in a keep-last-1 reader.
        if (!control(*req, status)) changed = true;
        return;
      case proto::Action::seek: conclude(*req, false, "seek: a live session cannot seek (replayers only: viscera-replay play)", status); return;
      case proto::Action::claim_instrument:
        // The scene state lists the instruments and their owners: a client sees there at once
        // that an instrument does not exist or is taken (Client::claim says which).
        switch (instruments.claim(req->instrument_id, req->client_id, proto::now_ns())) {
          case ClaimResult::claimed:
            event(proto::EventKind::instrument_claimed, req->instrument_id, req->client_id);
            changed = true;
            break;
          case ClaimResult::unknown_instrument: ++counted.unknown_instrument; break;
          case ClaimResult::already_owner:
          case ClaimResult::taken: break;  // no fault: its owner may let it go
        }
        return;
      case proto::Action::take_over:
      case proto::Action::hand_back:
        hand_over(*req, status);
        changed = true;
        return;
      case proto::Action::release_instrument:
        switch (instruments.release(req->instrument_id, req->client_id)) {
          case ReleaseResult::released:
            event(proto::EventKind::instrument_released, req->instrument_id, req->client_id, "released by its owner", 0,
                  proto::EventReason::by_owner);
            changed = true;
            break;
          case ReleaseResult::not_owner: ++counted.not_owner; break;
          case ReleaseResult::unknown_instrument: ++counted.unknown_instrument; break;
        }
        return;
    }
  };
  if (step)
    for (const auto& payload : step->requests) take(payload, std::nullopt);
  else
    endpoints.take_session_requests([&](const proto::Received& r) { take(r.payload, Sender{r.participant, r.identity}); });
  if (changed) publish_scene();
}

/// Run-time control: a new physics rate at once; a scene or material is prepared in the
/// background (finish_preparing() swaps it in). Every request gets an outcome in the scene state
/// and an event; a refusal says why.
bool SimulationServer::Impl::control(const proto::SessionRequest& req, const Status& status) {
  const auto refuse = [&](const std::string& why) {
    conclude(req, false, why, status);
    return true;
  };
  if (req.action == proto::Action::set_physics_rate) {
    // Whole hertz, as in scene files: the tick grid's period is 1/rate.
    if (req.physics_rate_hz != std::floor(req.physics_rate_hz))
      return refuse("physics rate " + common::short_number(req.physics_rate_hz) + " Hz: whole hertz only");
    try {
      check_tick_budget(organ->integrator->dt_s(), organ->substep_cost_s, req.physics_rate_hz, budget, "set_physics_rate", "physics_rate_hz");
      // A slower rate takes more sub-steps a tick: the stiffened ones may no longer fit it.
      check_stiffening(organ->model_recipe.mechanisms, scene.largest_edge_strain,
                       allowed_substep_growth(organ->integrator->dt_s(), organ->substep_cost_s, req.physics_rate_hz, budget),
                       "set_physics_rate " + common::short_number(req.physics_rate_hz) + " Hz (material " + organ->material.name + ")");
    } catch (const InputError& e) {
      return refuse(e.what());
    }
    char text[160];
    std::snprintf(text, sizeof text, "physics rate %.0f Hz (was %.0f Hz): ", req.physics_rate_hz, scene.physics_rate_hz);
    scene.physics_rate_hz = req.physics_rate_hz;
    conclude(req, true, text + tick_cost(organ->integrator->dt_s(), organ->substep_cost_s, scene.physics_rate_hz), status);
    return true;
  }
  // The material is rebuilt on the organ's mesh in the background; a cut organ's mesh changes
  // under the physics thread, and its model carries what the cuts made.
  if (req.action == proto::Action::set_material && organ->cuts > 0)
    return refuse("the organ has been cut: a material change applies to an uncut organ (load the scene again first)");
  // A material file that does not read is refused at once, as the background build would; busy
  // first, so that a flood of files costs the physics thread no parse while one is being built.
  if (!session.preparing().empty()) return refuse("busy: still preparing " + session.preparing());
  if (req.action == proto::Action::set_material && req.material.file_text) {
    try {
      tissue::parse_material(*req.material.file_text, "set_material");
    } catch (const InputError& e) {
      return refuse("material file " + req.material.file_name + ": " + e.what());
    }
  }
  const auto refused =
      req.action == proto::Action::load_scene ? session.start_scene(req, scene.domain_id) : session.start_material(req, organ, scene.physics_rate_hz);
  if (refused) return refuse(*refused);
  if (status) status("client " + std::to_string(req.client_id) + " asked for " + session.preparing() + "; preparing it");
  return false;
}

/// Physics thread, between ticks: a prepared scene or material that is ready replaces the organ
/// (in lockstep, once it is ready: the tick that asked for it uses it).
void SimulationServer::Impl::finish_preparing(const Status& status) {
  if (lockstep) session.wait_ready();
  auto done = session.take_ready();
  if (!done) return;
  const bool new_scene = done->request.action == proto::Action::load_scene;
  if (!done->organ) return conclude(done->request, false, done->what + ": " + done->error, status);
  try {
    adopt(std::move(done->organ), new_scene);
  } catch (const std::exception& e) {
    return conclude(done->request, false, done->what + ": " + e.what(), status);
  }
  if (new_scene) session.refresh_scenes();
  conclude(done->request, true, (new_scene ? "loaded " : "changed to ") + done->what + " (" + organ->describe_step(scene.physics_rate_hz) + ")",
           status);
}

/// An instructor takes an instrument over from its owner, or hands it back: ownership moves in
/// one step (never free in between), with an event naming both clients and an outcome.
void SimulationServer::Impl::hand_over(const proto::SessionRequest& req, const Status& status) {
  const bool take = req.action == proto::Action::take_over;
  const std::string id = "instrument " + std::to_string(req.instrument_id);
  const Handover h = take ? instruments.take_over(req.instrument_id, req.client_id, proto::now_ns())
                          : instruments.hand_back(req.instrument_id, req.client_id, proto::now_ns());
  std::string message;
  switch (h.result) {
    case HandoverResult::handed_over:
      message = take ? (h.from ? id + " taken over from client " + std::to_string(h.from) : id + " was free: claimed")
                     : (h.from ? id + " handed back to client " + std::to_string(h.from) : id + " handed back: it was free, and is free again");
      break;
    case HandoverResult::already_owner: message = id + ": already this client's"; break;
    case HandoverResult::not_owner: message = id + ": not this client's to hand back"; break;
    case HandoverResult::not_taken_over: message = id + ": this client did not take it over"; break;
    case HandoverResult::unknown_instrument: message = "the scene has no " + id; break;
  }
  const bool accepted = h.result == HandoverResult::handed_over || h.result == HandoverResult::already_owner;
  session.record(req, accepted, message);
  if (h.result == HandoverResult::handed_over && !take && h.from == 0) {
    event(proto::EventKind::instrument_released, req.instrument_id, req.client_id, message, req.request_seq, proto::EventReason::handed_back);
  } else if (h.result == HandoverResult::handed_over) {
    // The new owner's claim names the one it came from; no release in between.
    const std::uint32_t to = take ? req.client_id : h.from;
    event(proto::EventKind::instrument_claimed, req.instrument_id, to, message, req.request_seq);
  } else if (!accepted) {
    event(proto::EventKind::request_refused, req.instrument_id, req.client_id, message, req.request_seq);
  }
  if (status) status("client " + std::to_string(req.client_id) + " " + proto::action_name(req.action) + ": " + message);
}

/// A control request's outcome: in the scene state (the last 8), as an event, on the console.
void SimulationServer::Impl::conclude(const proto::SessionRequest& req, bool accepted, const std::string& message, const Status& status) {
  session.record(req, accepted, message);
  if (accepted && req.action != proto::Action::load_scene) {
    nlohmann::json change = proto::to_json(req);
    change["tick"] = current_tick();
    loaded.changes.push_back(std::move(change));
  }
  const proto::EventKind kind = !accepted                                   ? proto::EventKind::request_refused
                                : req.action == proto::Action::load_scene   ? proto::EventKind::scene_loaded
                                : req.action == proto::Action::set_material ? proto::EventKind::material_changed
                                                                            : proto::EventKind::physics_rate_changed;
  event(kind, 0, req.client_id, message.substr(0, 1000), req.request_seq, proto::EventReason::unspecified,
        kind == proto::EventKind::scene_loaded ? req.scene_name : std::string());
  if (status)
    status("client " + std::to_string(req.client_id) + " " + proto::action_name(req.action) + ": " + (accepted ? "" : "refused: ") + message);
  publish_scene();
  if (accepted) publish_scene_files();
}

/// A client that died or went silent for longer than the lease loses its instrument, which is
/// released safely (no force on the tissue from it any more). Checked every tick; a gap of more
/// than kServerStall between two checks is the server's own stall (stopped, swapped out, a paused
/// VM: the commands that came meanwhile wait in its socket, unread), not its clients' silence. A
/// client that died during it is released one lease after the server runs again.
void SimulationServer::Impl::release_silent(const Status& status) {
  constexpr std::int64_t kServerStall = 100'000'000;  // [ns]: 100 ticks at 1 kHz, the default tick budget
  const std::int64_t now = proto::now_ns();
  if (last_silence_check_ns != 0 && now - last_silence_check_ns > kServerStall) instruments.excuse_stall(now - last_silence_check_ns);
  last_silence_check_ns = now;
  const auto released = instruments.release_silent(now, std::chrono::nanoseconds(proto::kLivelinessLease).count());
  for (const auto& o : released) {
    const std::string id = "instrument " + std::to_string(o.instrument_id);
    if (o.handed_back_to != 0) {
      const std::string message = id + " handed back to client " + std::to_string(o.handed_back_to) + ": client " + std::to_string(o.owner) +
                                  ", which had taken it over, silent for more than the lease";
      if (status) status(message);
      event(proto::EventKind::instrument_claimed, o.instrument_id, o.handed_back_to, message);
      continue;
    }
    if (status) status(id + " released: client " + std::to_string(o.owner) + " silent for more than the lease");
    event(proto::EventKind::instrument_released, o.instrument_id, o.owner, "owner silent for more than the lease", 0,
          proto::EventReason::owner_silent);
  }
  if (!released.empty()) publish_scene();
}

}  // namespace viscera::runtime
