#include "viscera/runtime/simulation_server.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>

#include <pthread.h>

#include <nlohmann/json.hpp>

#include "viscera/common/input_error.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/protocol/request_json.hpp"
#include "viscera/runtime/build_info.hpp"
#include "viscera/runtime/command_responder.hpp"
#include "viscera/runtime/instrument_table.hpp"
#include "viscera/runtime/mesh_publisher.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/session_control.hpp"
#include "viscera/runtime/simulated_tool.hpp"
#include "viscera/runtime/tick_grid.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

namespace viscera::runtime {

namespace proto = viscera::protocol;
using namespace viscera::tissue;
using common::InputError;
using Status = std::function<void(const std::string&)>;

namespace {
/// The server's version and build: a session re-simulates bit for bit on the same build.
std::string server_build() { return std::string("viscera-server ") + VISCERA_BUILD; }
}  // namespace

struct SimulationServer::Impl {
  // Two threads: the physics thread (run()) steps the organ at the fixed rate; the command thread
  // answers every command the moment it arrives (CommandResponder), so the round trip never waits
  // for a step. The organ is the physics thread's; session control replaces it between ticks, and
  // the command thread reads it (compliance, contact queries) only while holding organ_mutex,
  // which the physics thread takes to swap it.
  SceneSpec scene;  // physics thread: the running scene (its rate may change at run time)
  ServerEndpoints& endpoints;
  TickBudget budget;
  const std::atomic<bool>* stop = nullptr;  // run()'s stop flag: a long tick checks it between sub-steps
  std::shared_ptr<Organ> organ;  // shared with a material change being prepared from it
  std::mutex organ_mutex;
  State state;
  double sim_time_s = 0;
  std::uint64_t ticks_run = 0;  // physics thread; the tick in progress (or the next) is ticks_run + 1
  std::uint32_t generation = 1;  // +1 per scene loaded: the surface's mesh_id
  bool paused = false;
  // What the scene was loaded with and changed by since (SceneFiles, for recordings).
  std::uint64_t scene_first_tick = 1;
  double scene_sim_time_s = 0;
  nlohmann::json scene_changes = nlohmann::json::array();
  // Lockstep (run_lockstep): no wall clock, no lease, builds waited for; forces and events of the
  // tick go into its result.
  bool lockstep = false;
  proto::LockstepResult* capture = nullptr;

  InstrumentTable instruments;  // both threads (thread-safe)
  struct Tool {  // physics thread only
    SimulatedTool tool;
    std::unique_ptr<ProbeContact> contact;
    ContactResult result;
  };
  std::map<std::uint32_t, Tool> tools;
  CommandResponder responder;
  SessionControl session;
  std::unique_ptr<MeshPublisher> mesh_publisher;  // its own thread
  std::uint64_t mesh_frames_before = 0, mesh_skipped_before = 0;  // of the publishers of earlier scenes
  std::atomic<std::uint64_t> rejected_malformed{0}, rejected_not_owner{0}, rejected_unknown_instrument{0}, forces_sent{0};
  ServerStats stats;  // physics thread

  Impl(const SceneSpec& s, ServerEndpoints& e, std::string dir, const TickBudget& b, bool lockstep_mode)
      : scene(s),
        endpoints(e),
        budget(b),
        lockstep(lockstep_mode),
        session(
            std::move(dir), [b](const SceneSpec& spec) { return std::shared_ptr<Organ>(build_organ(spec, b)); },
            [b](const std::shared_ptr<const Organ>& current, const proto::MaterialChange& change, double rate_hz) {
              return std::shared_ptr<Organ>(rebuild_with_material(*current, change, rate_hz, b));
            }) {
    adopt(build_organ(s, budget), true);
    publish_scene();
    publish_scene_files();
  }

  /// The tick in progress, or between ticks the next one.
  std::uint64_t current_tick() const { return ticks_run + 1; }

  // --- The organ ----------------------------------------------------------------------------

  /// Physics thread, between ticks: `next` becomes the organ. A new scene starts at rest with its
  /// own instruments (owners lose theirs and must claim again) and a new surface; a new material
  /// on the same mesh keeps the organ's deformation, its owners and its tools.
  void adopt(std::shared_ptr<Organ> next, bool new_scene) {
    next->integrator->boundary_conditions().force_field = [this](const BoundaryConditions::FieldEvaluation& e) { apply_instruments(e); };
    next->integrator->set_interruption([this] { return stop && stop->load(); });
    std::vector<Ownership> released;
    std::shared_ptr<Organ> old;
    {
      std::lock_guard world(organ_mutex);
      old = std::move(organ);
      organ = std::move(next);
      const double rate = scene.physics_rate_hz;
      scene = organ->scene;
      if (new_scene) {
        released = instruments.replace(scene.instruments);
        tools.clear();
        for (const auto& spec : scene.instruments)
          tools.emplace(spec.id, Tool{SimulatedTool(spec),
                                      std::make_unique<ProbeContact>(organ->boundary.triangles, organ->mesh->nodes, spec.tip_radius_m,
                                                                     scene.contact_stiffness_n_per_m, 0.02, scene.contact_damping_s_per_m),
                                      {}});
        responder.set_instruments(scene.instruments, organ->boundary.triangles, organ->mesh->nodes, scene.contact_stiffness_n_per_m);
        state = State::at_rest(*organ->mesh);
        if (old) ++generation;
        scene_first_tick = current_tick();
        scene_sim_time_s = sim_time_s;
        scene_changes = nlohmann::json::array();
      } else {
        scene.physics_rate_hz = rate;  // a set_physics_rate outlives a material change
        if (state.memory.size() != organ->model->memory_size()) state.memory.clear();  // relaxed
      }
      publish_snapshot(ticks_run);
    }
    for (const auto& o : released) event(proto::EventKind::instrument_released, o.instrument_id, o.owner, "the scene was replaced by " + scene.name);
    if (new_scene && !lockstep) {
      if (mesh_publisher) {
        mesh_frames_before += mesh_publisher->frames_published();
        mesh_skipped_before += mesh_publisher->frames_skipped();
      }
      mesh_publisher.reset();
      if (scene.mesh_rate_hz > 0)
        mesh_publisher = std::make_unique<MeshPublisher>(endpoints.open_mesh_stream(), surface_topology(organ->boundary), organ->boundary.nodes,
                                                         scene.mesh_rate_hz);
    }
    session.retire(std::move(old));
  }

  /// The organ back at rest (memory variables relaxed); graspers let go.
  void reset_organ() {
    state = State::at_rest(*organ->mesh);
    for (auto& [id, t] : tools) t.tool.let_go();
  }

  /// The instruments' forces on the organ (the integrator's force field, taken implicitly):
  /// contact of each active tool, and the springs holding grasped nodes to the jaws.
  void apply_instruments(const BoundaryConditions::FieldEvaluation& e) {
    for (auto& [id, t] : tools) {
      if (!t.tool.active()) {
        t.result = {};
        continue;
      }
      t.result = t.contact->apply(t.tool.position(), t.tool.velocity(), e);
      if (!t.tool.held().empty()) add_grasp(t.result, t.tool.held().apply(t.tool.position(), t.tool.orientation(), t.tool.velocity(), e));
    }
  }

  /// The boundary surface with its vertices numbered in the order of boundary.nodes.
  proto::SurfaceTopology surface_topology(const BoundarySurface& boundary) const {
    proto::SurfaceTopology t;
    t.mesh_id = generation;
    t.organ_name = scene.name;
    t.vertex_count = static_cast<std::uint32_t>(boundary.nodes.size());
    const auto& nodes = organ->mesh->nodes;
    std::vector<std::uint32_t> vertex_of(nodes.size(), 0);
    for (std::size_t k = 0; k < boundary.nodes.size(); ++k) {
      vertex_of[boundary.nodes[k]] = static_cast<std::uint32_t>(k);
      for (int d = 0; d < 3; ++d) t.rest_positions.push_back(static_cast<float>(nodes[boundary.nodes[k]][d]));
    }
    for (const auto& tri : boundary.triangles)
      for (const auto n : tri) t.triangles.push_back(vertex_of[n]);
    return t;
  }

  // --- What the server publishes ------------------------------------------------------------

  void publish_scene() {
    proto::Scene sc;
    sc.name = scene.name;
    sc.physics_rate_hz = scene.physics_rate_hz;
    sc.paused = paused;
    sc.instruments = instruments.describe();
    const Box& bounds = organ->bounds;
    sc.bounds_min = {bounds.lo.x(), bounds.lo.y(), bounds.lo.z()};
    sc.bounds_max = {bounds.hi.x(), bounds.hi.y(), bounds.hi.z()};
    sc.generation = generation;
    sc.material = organ->material_info();
    sc.regions = organ->region_info();
    sc.available_scenes = session.scenes().loadable;
    for (const auto& [name, error] : session.scenes().unreadable) sc.unreadable_scenes.push_back(name + ": " + error.substr(0, 300));
    sc.preparing = session.preparing();
    sc.recent_requests.assign(session.outcomes().begin(), session.outcomes().end());
    endpoints.write_scene(proto::encode(sc));
  }

  /// What it takes to re-run the scene (recordings): its files, the server's build and settings,
  /// the material and rate changes since it was loaded, its first tick.
  void publish_scene_files() {
    proto::SceneFiles f;
    f.generation = generation;
    f.server_version = server_build();
    f.files = organ->sources;
    f.first_tick = scene_first_tick;
    f.sim_time_s = scene_sim_time_s;
    const nlohmann::json settings = {{"max_tick_ms", 1e3 * budget.max_tick_s},
                                     {"scene_dir", session.scene_dir()},
                                     {"physics_rate_hz", scene.physics_rate_hz},
                                     {"changes", scene_changes}};
    f.settings_json = settings.dump();
    endpoints.write_scene_files(proto::encode(f));
  }

  /// A session event for recorders, trainers and consoles (physics thread), stamped with the tick
  /// in progress (the request it concludes, if any).
  void event(proto::EventKind kind, std::uint32_t instrument_id, std::uint32_t client_id, std::string text = {}, std::uint64_t request_seq = 0) {
    auto payload =
        proto::encode(proto::Event{0, kind, instrument_id, client_id, sim_time_s, proto::now_ns(), std::move(text), current_tick(), request_seq});
    if (capture)
      capture->events.push_back(std::move(payload));
    else
      endpoints.write_event(payload);
  }

  /// After tick `tick` (physics thread): the command thread answers from this state from now on.
  void publish_snapshot(std::uint64_t tick) {
    auto snap = std::make_shared<Snapshot>();
    snap->tick = tick;
    snap->max_edge_strain = organ->integrator->max_edge_strain();
    snap->x = state.x;
    for (const auto& [id, t] : tools)
      if (!t.tool.held().empty()) snap->grasped[id] = t.tool.held();
    responder.publish(std::move(snap));
  }

  /// `tick`: the tick that stepped with the command, or whose state answered it; `strain`: the
  /// organ's largest edge strain that tick.
  void publish_force(std::uint32_t id, std::uint32_t owner, const proto::Command& command, const ContactResult& r, std::int64_t step_time_ns,
                     std::uint64_t tick, double strain) {
    proto::Force f = force_message(id, owner, command, r, local_stiffness(r, *organ->compliance, lockstep), proto::now_ns(), step_time_ns);
    f.tick = tick;
    f.max_edge_strain = strain;
    auto payload = proto::encode(f);
    if (capture)
      capture->forces.push_back(std::move(payload));
    else
      endpoints.write_force(id, payload);
    ++forces_sent;
  }

  /// After a tick: every active tool's force, and its contact and grasp events.
  void publish_forces(std::int64_t step_time_ns) {
    for (auto& [id, t] : tools) {
      if (t.tool.active())
        publish_force(id, t.tool.owner(), t.tool.command(), t.result, std::max<std::int64_t>(step_time_ns, 1), current_tick(),
                      organ->integrator->max_edge_strain());
      if (const ToolEvent e = t.tool.update_contact(t.result.in_contact, sim_time_s); e != ToolEvent::none)
        event(e == ToolEvent::contact_started ? proto::EventKind::contact_started : proto::EventKind::contact_ended, id, t.tool.owner());
    }
  }

  // --- Commands (command thread) ------------------------------------------------------------

  /// A command's payload decoded, or counted as malformed.
  std::optional<proto::Command> decode_counted(std::span<const std::uint8_t> payload) {
    std::string why;
    auto c = proto::decode_command(payload, &why);
    if (!c) ++rejected_malformed;
    return c;
  }

  /// A command offered to its instrument, a refusal counted; whether it became the newest.
  bool offer_counted(const proto::Command& c, std::int64_t now_ns) {
    switch (instruments.command(c, now_ns)) {
      case CommandResult::accepted: return true;
      case CommandResult::stale: return false;
      case CommandResult::not_owner: ++rejected_not_owner; return false;
      case CommandResult::unknown_instrument: ++rejected_unknown_instrument; return false;
    }
    return false;
  }

  /// Each valid command from an instrument's owner becomes the instrument's newest command and is
  /// answered at once with the reaction at the commanded pose on the newest snapshot (contact
  /// query, no step). The next tick steps the tissue with it.
  void answer_new_commands() {
    struct Update {
      std::uint32_t id, owner;
      proto::Command command;
    };
    std::vector<Update> updated;
    std::lock_guard world(organ_mutex);  // the organ and the responder's queries stay while we answer
    endpoints.take_commands([&](const proto::Received& r) {
      const auto c = decode_counted(r.payload);
      if (c && offer_counted(*c, proto::now_ns())) updated.push_back({c->instrument_id, c->client_id, *c});
    });
    for (const auto& u : updated) {
      std::uint64_t tick = 0;
      double strain = 0;
      const ContactResult r = responder.answer(u.id, u.command, &tick, &strain);
      publish_force(u.id, u.owner, u.command, r, 0, tick, strain);
    }
  }

  /// Lockstep: the step's answers, on the state the previous tick left (as the command thread
  /// answers them live); they do not become the instruments' commands. Ownership is not checked
  /// again: the live server answered them, so their client owned the instrument then, and a claim
  /// or release in the same step may have come before or after them live (the order of the two
  /// within one tick's interval is not recorded).
  void answer_in_lockstep(const std::vector<std::vector<std::uint8_t>>& answers) {
    for (const auto& payload : answers) {
      const auto c = decode_counted(payload);
      if (!c) continue;
      if (!instruments.owner(c->instrument_id)) {
        ++rejected_unknown_instrument;
        continue;
      }
      std::uint64_t tick = 0;
      double strain = 0;
      const ContactResult r = responder.answer(c->instrument_id, *c, &tick, &strain);
      publish_force(c->instrument_id, c->client_id, *c, r, 0, tick, strain);
    }
  }

  /// Lockstep: the step's commands become their instruments' newest (the live command thread's
  /// other half).
  void command_in_lockstep(const std::vector<std::vector<std::uint8_t>>& commands) {
    for (const auto& payload : commands)
      if (const auto c = decode_counted(payload)) offer_counted(*c, 0);
  }

  // --- Session requests (physics thread) -----------------------------------------------------

  /// Claim and release an instrument (its owner only); pause, resume and reset the organ, load a
  /// scene, change the material or the physics rate (any client: an instructor's console or a
  /// trainer).
  void take_sessions(const Status& status, const proto::LockstepStep* step) {
    bool changed = false;
    const auto take = [&](std::span<const std::uint8_t> payload) {
      std::string why;
      const auto req = proto::decode_session_request(payload, &why);
      if (!req) {
        ++rejected_malformed;
        return;
      }
      const std::string who = "client " + std::to_string(req->client_id);
      switch (req->action) {
        case proto::Action::pause:
        case proto::Action::resume:
          if (paused != (req->action == proto::Action::pause)) {
            if (status) status(who + (paused ? " resumed" : " paused") + " the simulation");
            event(paused ? proto::EventKind::resumed : proto::EventKind::paused, 0, req->client_id);
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
          control(*req, status);
          changed = true;
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
            case ClaimResult::unknown_instrument: ++rejected_unknown_instrument; break;
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
              event(proto::EventKind::instrument_released, req->instrument_id, req->client_id, "released by its owner");
              changed = true;
              break;
            case ReleaseResult::not_owner: ++rejected_not_owner; break;
            case ReleaseResult::unknown_instrument: ++rejected_unknown_instrument; break;
          }
          return;
      }
    };
    if (step)
      for (const auto& payload : step->requests) take(payload);
    else
      endpoints.take_session_requests([&](const proto::Received& r) { take(r.payload); });
    if (changed) publish_scene();
  }

  /// Run-time control: a new physics rate at once; a scene or material is prepared in the
  /// background (finish_preparing() swaps it in). Every request gets an outcome in the scene state
  /// and an event; a refusal says why.
  void control(const proto::SessionRequest& req, const Status& status) {
    const auto refuse = [&](const std::string& why) { conclude(req, false, why, status); };
    if (req.action == proto::Action::set_physics_rate) {
      // Whole hertz, as in scene files: the tick grid's period is 1/rate.
      if (req.physics_rate_hz != std::floor(req.physics_rate_hz))
        return refuse("physics rate " + common::short_number(req.physics_rate_hz) + " Hz: whole hertz only");
      try {
        check_tick_budget(organ->integrator->dt_s(), organ->substep_cost_s, req.physics_rate_hz, budget, "set_physics_rate", "physics_rate_hz");
      } catch (const InputError& e) {
        return refuse(e.what());
      }
      char text[160];
      std::snprintf(text, sizeof text, "physics rate %.0f Hz (was %.0f Hz): ", req.physics_rate_hz, scene.physics_rate_hz);
      scene.physics_rate_hz = req.physics_rate_hz;
      conclude(req, true, text + tick_cost(organ->integrator->dt_s(), organ->substep_cost_s, scene.physics_rate_hz), status);
      return;
    }
    const auto refused = req.action == proto::Action::load_scene ? session.start_scene(req, scene.domain_id)
                                                                 : session.start_material(req, organ, scene.physics_rate_hz);
    if (refused) return refuse(*refused);
    if (status) status("client " + std::to_string(req.client_id) + " asked for " + session.preparing() + "; preparing it");
  }

  /// Physics thread, between ticks: a prepared scene or material that is ready replaces the organ
  /// (in lockstep, once it is ready: the tick that asked for it uses it).
  void finish_preparing(const Status& status) {
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

  /// A control request's outcome: in the scene state (the last 8), as an event, on the console.
  /// An instructor takes an instrument over from its owner, or hands it back: ownership moves in
  /// one step (never free in between), with an event naming both clients and an outcome.
  void hand_over(const proto::SessionRequest& req, const Status& status) {
    const bool take = req.action == proto::Action::take_over;
    const std::string id = "instrument " + std::to_string(req.instrument_id);
    const Handover h = take ? instruments.take_over(req.instrument_id, req.client_id, proto::now_ns())
                            : instruments.hand_back(req.instrument_id, req.client_id, proto::now_ns());
    std::string message;
    switch (h.result) {
      case HandoverResult::handed_over:
        message = take ? (h.from ? id + " taken over from client " + std::to_string(h.from) : id + " was free: claimed")
                       : id + " handed back to client " + std::to_string(h.from);
        break;
      case HandoverResult::already_owner: message = id + ": already this client's"; break;
      case HandoverResult::not_owner: message = id + ": not this client's to hand back"; break;
      case HandoverResult::not_taken_over: message = id + ": this client did not take it over"; break;
      case HandoverResult::unknown_instrument: message = "the scene has no " + id; break;
    }
    const bool accepted = h.result == HandoverResult::handed_over || h.result == HandoverResult::already_owner;
    session.record(req, accepted, message);
    if (h.result == HandoverResult::handed_over) {
      // The new owner's claim names the one it came from; no release in between.
      const std::uint32_t to = take ? req.client_id : h.from;
      event(proto::EventKind::instrument_claimed, req.instrument_id, to, message, req.request_seq);
    } else if (!accepted) {
      event(proto::EventKind::request_refused, req.instrument_id, req.client_id, message, req.request_seq);
    }
    if (status) status("client " + std::to_string(req.client_id) + " " + proto::action_name(req.action) + ": " + message);
  }

  void conclude(const proto::SessionRequest& req, bool accepted, const std::string& message, const Status& status) {
    session.record(req, accepted, message);
    if (accepted && req.action != proto::Action::load_scene) {
      nlohmann::json change = proto::to_json(req);
      change["tick"] = current_tick();
      scene_changes.push_back(std::move(change));
    }
    const proto::EventKind kind = !accepted                                   ? proto::EventKind::request_refused
                                  : req.action == proto::Action::load_scene   ? proto::EventKind::scene_loaded
                                  : req.action == proto::Action::set_material ? proto::EventKind::material_changed
                                                                              : proto::EventKind::physics_rate_changed;
    event(kind, 0, req.client_id, message.substr(0, 1000), req.request_seq);
    if (status)
      status("client " + std::to_string(req.client_id) + " " + proto::action_name(req.action) + ": " + (accepted ? "" : "refused: ") + message);
    publish_scene();
    if (accepted) publish_scene_files();
  }

  /// A client that died or went silent for longer than the lease loses its instrument, which is
  /// released safely (no force on the tissue from it any more).
  void release_silent(const Status& status) {
    const auto released = instruments.release_silent(proto::now_ns(), std::chrono::nanoseconds(proto::kLivelinessLease).count());
    for (const auto& o : released) {
      if (status)
        status("instrument " + std::to_string(o.instrument_id) + " released: client " + std::to_string(o.owner) + " silent for more than the lease");
      event(proto::EventKind::instrument_released, o.instrument_id, o.owner, "owner silent for more than the lease");
    }
    if (!released.empty()) publish_scene();
  }

  // --- One tick (physics thread) -------------------------------------------------------------

  /// Session requests, a finished build, the lease; then the organ stepped by 1/rate with each
  /// owned instrument's newest command; then the snapshot, the forces and a surface frame.
  /// Returns the step's duration [ns].
  /// In lockstep (`step`), the requests and commands are the step's, and no lease runs out.
  std::int64_t tick(const Status& status, const proto::LockstepStep* step = nullptr) {
    take_sessions(status, step);
    finish_preparing(status);
    const double dt = 1.0 / scene.physics_rate_hz;  // session control may change it
    if (step)
      command_in_lockstep(step->commands);
    else
      release_silent(status);
    for (const TickCommand& c : instruments.tick_commands()) tools.at(c.instrument_id).tool.begin_tick(c.active, c.owner, c.command);
    const auto t0 = std::chrono::steady_clock::now();
    if (!paused) {
      for (auto& [id, t] : tools) {
        t.tool.move(dt, scene.max_tool_speed_m_s);
        if (const ToolEvent e = t.tool.update_grasp(organ->boundary.nodes, state.x, scene.grasp_stiffness_n_per_m); e == ToolEvent::grasped)
          event(proto::EventKind::grasped, id, t.tool.owner(), std::to_string(t.tool.held().size()) + " surface nodes");
        else if (e == ToolEvent::let_go)
          event(proto::EventKind::let_go, id, t.tool.owner());
      }
      try {
        organ->integrator->advance(state, dt);
        sim_time_s += dt;
      } catch (const SimulationError& e) {
        // Keep serving, but never stay stuck: the same input would fail again from the rolled-back
        // state, so the organ goes back to rest (memory variables relaxed) and graspers let go.
        reset_organ();
        ++stats.physics_resets;
        if (status) status(std::string("physics: ") + e.what() + "; organ reset to rest");
        event(proto::EventKind::physics_reset, 0, 0, e.what());
      }
    }
    const auto step_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
    publish_snapshot(current_tick());
    publish_forces(step_ns);
    if (mesh_publisher) mesh_publisher->offer(state.x, sim_time_s, proto::now_ns(), current_tick());
    ++ticks_run;
    ++stats.ticks;
    return step_ns;
  }

  /// The surface after the last tick, as the mesh publisher sends it.
  std::vector<std::uint8_t> surface_frame() const {
    proto::MeshFrame f;
    f.mesh_id = generation;
    f.frame = ticks_run;
    f.sim_time_s = sim_time_s;
    f.server_stamp_ns = proto::now_ns();
    f.tick = ticks_run;
    f.positions.resize(3 * organ->boundary.nodes.size());
    copy_surface(state.x, organ->boundary.nodes, f.positions.data());
    return proto::encode(f);
  }

  /// Lockstep: one step from the driver, and its result.
  proto::LockstepResult lockstep_tick(const proto::LockstepStep& step, bool first, const Status& status) {
    proto::LockstepResult result;
    result.tick = step.tick;
    if (first) {  // the recording's clock: its tick numbers and simulated time
      ticks_run = step.tick - 1;
      sim_time_s = step.sim_time_s;
      scene_first_tick = step.tick;
      scene_sim_time_s = sim_time_s;
      publish_snapshot(ticks_run);
    } else if (step.tick != current_tick()) {
      result.error = "step for tick " + std::to_string(step.tick) + ", expected tick " + std::to_string(current_tick());
      return result;
    }
    capture = &result;
    answer_in_lockstep(step.answers);
    tick(status, &step);
    capture = nullptr;
    result.sim_time_s = sim_time_s;
    if (step.want_frame) result.frame = surface_frame();
    return result;
  }

  /// The counters the other threads keep, into stats.
  void collect_counts() {
    stats.rejected_malformed = rejected_malformed;
    stats.rejected_not_owner = rejected_not_owner;
    stats.rejected_unknown_instrument = rejected_unknown_instrument;
    stats.rejected = stats.rejected_malformed + stats.rejected_not_owner + stats.rejected_unknown_instrument;
    stats.forces_sent = forces_sent;
    stats.mesh_frames = mesh_frames_before + (mesh_publisher ? mesh_publisher->frames_published() : 0);
    stats.mesh_frames_skipped = mesh_skipped_before + (mesh_publisher ? mesh_publisher->frames_skipped() : 0);
  }

  std::string status_now() const {
    int in_use = 0;
    double fmax = 0;
    for (const auto& [id, t] : tools) {
      in_use += t.tool.active();
      fmax = std::max(fmax, t.result.force_on_tool.norm());
    }
    return status_line(stats, paused, in_use, fmax);
  }
};

SimulationServer::SimulationServer(const SceneSpec& scene, ServerEndpoints& endpoints, const std::string& scene_dir, const TickBudget& budget,
                                   bool lockstep)
    : impl_(std::make_unique<Impl>(scene, endpoints,
                                   !scene_dir.empty() ? scene_dir
                                   : std::filesystem::path(scene.source).has_parent_path()
                                       ? std::filesystem::path(scene.source).parent_path().string()
                                       : std::string("."),
                                   budget, lockstep)) {}
SimulationServer::~SimulationServer() = default;

int SimulationServer::abandoned_work() { return SessionControl::abandoned(); }

std::string SimulationServer::describe() const {
  char b[400];
  std::snprintf(b, sizeof b, "scene %s: %zu nodes, %zu tets, model %s, %zu instruments, %.0f Hz, DDS domain %u, ", impl_->scene.name.c_str(),
                impl_->organ->mesh->node_count(), impl_->organ->mesh->tet_count(), std::string(impl_->organ->model->name()).c_str(),
                impl_->tools.size(), impl_->scene.physics_rate_hz, impl_->scene.domain_id);
  return b + impl_->organ->describe_step(impl_->scene.physics_rate_hz) + impl_->organ->describe_regions();
}

ServerStats SimulationServer::run_lockstep(const std::atomic<bool>& stop, LockstepLink& link, const Status& status) {
  Impl& s = *impl_;
  s.stop = &stop;
  bool first = true;
  while (!stop.load()) {
    link.take_steps(std::chrono::milliseconds(50), [&](std::span<const std::uint8_t> payload) {
      std::string why;
      const auto step = proto::decode_lockstep_step(payload, &why);
      proto::LockstepResult result;
      if (!step) {
        ++s.rejected_malformed;
        result.error = "not a lockstep step: " + why;
      } else {
        result = s.lockstep_tick(*step, first, status);
        first = first && !result.error.empty();
      }
      link.write_result(proto::encode(result));
    });
  }
  s.collect_counts();
  return s.stats;
}

ServerStats SimulationServer::run(const std::atomic<bool>& stop, double duration_s, const Status& status) {
  Impl& s = *impl_;
  s.stop = &stop;
  using clock = std::chrono::steady_clock;
  // The command thread answers commands as they arrive, on the other core, while this thread steps.
  std::atomic<bool> stopping{false};
  std::thread command_thread([&] {
    pthread_setname_np(pthread_self(), "command");
    while (!stopping.load())
      if (s.endpoints.wait_commands(std::chrono::milliseconds(20))) s.answer_new_commands();
  });
  struct Join {
    std::atomic<bool>& stopping;
    std::thread& thread;
    ~Join() {
      stopping = true;
      thread.join();
    }
  } join{stopping, command_thread};

  const auto start = clock::now();
  TickGrid grid(start.time_since_epoch());  // 1 kHz slots fixed from here: simulated time keeps wall time
  auto next = start;  // when this tick was meant to start: its slot's start, or at once after a late tick
  auto last_report = start;
  ServerStatistics statistics;
  while (!stop.load()) {
    const auto tick_start = clock::now();
    const std::int64_t step_ns = s.tick(status);
    statistics.tick(1e-3 * static_cast<double>(step_ns), std::chrono::duration<double, std::micro>(tick_start - next).count());
    const auto t1 = clock::now();
    if (t1 - last_report >= std::chrono::seconds(1)) {
      statistics.close_window(std::chrono::duration<double>(t1 - last_report).count(), s.stats);
      s.collect_counts();
      s.endpoints.write_telemetry(proto::encode(telemetry_report(s.stats, proto::now_ns())));
      if (status) status(s.status_now());
      last_report = t1;
    }
    if (duration_s > 0 && std::chrono::duration<double>(t1 - start).count() >= duration_s) break;
    // A late tick is followed at once in its own slot; slots that passed with no tick are counted
    // missed and skipped, never made up in a burst (tick_grid.hpp).
    const auto now = clock::now();
    next =
        clock::time_point(grid.tick_ended(now.time_since_epoch(), std::chrono::nanoseconds(static_cast<long long>(1e9 / s.scene.physics_rate_hz))));
    s.stats.late_ticks = grid.late_ticks();
    s.stats.missed_slots = grid.missed_slots();
    wait_for_slot<clock>(next);
  }
  s.collect_counts();
  return s.stats;
}

}  // namespace viscera::runtime
