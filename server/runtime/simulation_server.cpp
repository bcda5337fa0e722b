#include "viscera/runtime/simulation_server.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <pthread.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"
#include "viscera/runtime/grasp_hold.hpp"
#include "viscera/runtime/mesh_publisher.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/probe_contact.hpp"
#include "viscera/runtime/tick_grid.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/messages.hpp"

namespace viscera::runtime {

using common::InputError;
using common::short_number;

namespace proto = viscera::protocol;
using namespace viscera::tissue;

namespace {
std::atomic<int> g_abandoned{0};

/// Lets a background build or destruction finish on a thread of its own instead of waiting for it.
void abandon(std::future<void> f) {
  ++g_abandoned;
  std::thread([f = std::move(f)]() mutable { f.wait(); }).detach();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}
}  // namespace

struct SimulationServer::Impl {
  SceneSpec scene;  // physics thread: the running scene (its rate may change at run time)
  std::string scene_dir;
  // The organ (mesh, model, integrator, compliance) is the physics thread's. Session control
  // replaces it between ticks; the command thread reads it (compliance, instruments' queries)
  // only while holding organ_mutex, which the physics thread takes to swap it.
  std::shared_ptr<Organ> organ;  // shared with a material change being prepared from it
  std::mutex organ_mutex;
  TickBudget budget;
  const std::atomic<bool>* stop = nullptr;  // run()'s stop flag: a long tick checks it between sub-steps
  State state;
  double sim_time_s = 0;
  std::uint32_t generation = 1;  // +1 per scene loaded: the surface's mesh_id

  // Two threads: the physics thread (run()) steps the organ at the fixed rate; the command thread
  // answers every command the moment it arrives with the reaction at the commanded pose on the
  // newest published state (a Snapshot), so the round trip never waits for a step.
  struct Instrument {
    InstrumentSpec spec;
    // Shared, guarded by command_mutex: who owns it and the newest command.
    std::uint32_t owner = 0;
    bool has_command = false;
    std::int64_t last_heard_ns = 0;  // owner's last command or claim
    proto::Command last;
    // Physics thread only.
    std::unique_ptr<ProbeContact> contact;
    bool active = false;       // owned and commanded during the current tick
    std::uint32_t tick_owner = 0;
    proto::Command tick;       // the command the current tick steps with
    // The simulated tool: follows the commanded tip at most at the scene's tool speed limit in
    // simulated time, so a server that runs slower than real time (or a jumping device) never
    // drives the tool through the tissue within one tick.
    Vec3 proxy = Vec3::Zero();
    Vec3 proxy_velocity = Vec3::Zero();  // its motion over the current tick [m/s]
    GraspHold grasped;  // grasper: the tissue held by the closed jaws
    ContactResult result;
    bool touching = false;    // in contact (for contact events, with hysteresis)
    double last_touch_s = 0;  // simulated time it last touched
    // Command thread only: its own contact query (ProbeContact keeps scratch space).
    std::unique_ptr<ProbeContact> query;
  };
  std::map<std::uint32_t, Instrument> instruments;
  std::mutex command_mutex;

  /// What the command thread answers from: the organ after the last tick and the grasped nodes.
  struct Snapshot {
    std::vector<Vec3> x;
    std::map<std::uint32_t, GraspHold> grasped;
  };
  std::mutex snapshot_mutex;  // guards the pointer only; a Snapshot is never changed once shared
  std::shared_ptr<const Snapshot> snapshot;
  std::shared_ptr<const Snapshot> latest_snapshot() {
    std::lock_guard lock(snapshot_mutex);
    return snapshot;
  }
  bool paused = false;  // physics thread

  proto::Participant participant;
  proto::Reader commands, sessions;
  proto::Writer forces, scene_state, telemetry, events;
  std::unique_ptr<MeshPublisher> mesh_publisher;  // its own thread; after the writers it uses
  std::uint64_t mesh_frames_before = 0, mesh_skipped_before = 0;  // of the publishers of earlier scenes
  std::atomic<std::uint64_t> rejected_malformed{0}, rejected_not_owner{0}, rejected_unknown_instrument{0}, forces_sent{0};

  // Session control: a scene or material is built on a thread of its own while the physics goes
  // on; the physics thread swaps it in when ready. One at a time.
  struct Preparing {
    std::future<std::shared_ptr<Organ>> organ;
    proto::SessionRequest request;
    std::string what;
  };
  std::optional<Preparing> preparing;
  std::deque<proto::RequestOutcome> outcomes;  // the last 8, for the scene state
  SceneListing scenes;
  std::vector<std::future<void>> retiring;  // organs being destroyed (a compliance worker may be mid-factorisation)

  Impl(const SceneSpec& s, std::string dir, const TickBudget& b)
      : scene(s),
        scene_dir(std::move(dir)),
        budget(b),
        participant(s.domain_id),
        commands(participant, proto::Stream::instrument_command),
        sessions(participant, proto::Stream::session_request),
        forces(participant, proto::Stream::force_feedback),
        scene_state(participant, proto::Stream::scene_state),
        telemetry(participant, proto::Stream::telemetry),
        events(participant, proto::Stream::event) {
    scenes = list_scenes(scene_dir);
    adopt(build_organ(s, budget), true);
    publish_scene();
  }

  ~Impl() {
    // A stop never waits for an organ still being built or destroyed (the 96k liver takes seconds):
    // it finishes on a thread of its own, holding what it uses.
    if (preparing) abandon(std::async(std::launch::deferred, [f = std::move(preparing->organ)]() mutable { f.wait(); }));
    for (auto& f : retiring)
      if (f.wait_for(std::chrono::seconds(0)) != std::future_status::ready) abandon(std::move(f));
  }

  /// The instruments of the scene, each with its contact on the organ's surface.
  std::map<std::uint32_t, Instrument> make_instruments(const Organ& o) const {
    std::map<std::uint32_t, Instrument> made;
    for (const auto& spec : o.scene.instruments) {
      Instrument& inst = made[spec.id];
      inst.spec = spec;
      inst.contact = std::make_unique<ProbeContact>(o.boundary.triangles, o.mesh->nodes, spec.tip_radius_m, o.scene.contact_stiffness_n_per_m,
                                                    0.02, o.scene.contact_damping_s_per_m);
      inst.query = std::make_unique<ProbeContact>(o.boundary.triangles, o.mesh->nodes, spec.tip_radius_m, o.scene.contact_stiffness_n_per_m);
    }
    return made;
  }

  /// Physics thread, between ticks: `next` becomes the organ. A new scene starts at rest with its
  /// own instruments (owners lose theirs and must claim again) and a new surface; a new material
  /// on the same mesh keeps the organ's deformation, its owners and its tools.
  void adopt(std::shared_ptr<Organ> next, bool new_scene) {
    next->integrator->boundary_conditions().force_field = [this](const BoundaryConditions::FieldEvaluation& e) { apply_instruments(e); };
    next->integrator->set_interruption([this] { return stop && stop->load(); });
    std::map<std::uint32_t, Instrument> made;
    if (new_scene) made = make_instruments(*next);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> released;  // instrument, owner
    std::shared_ptr<Organ> old;
    {
      std::lock_guard world(organ_mutex);
      std::lock_guard lock(command_mutex);
      old = std::move(organ);
      organ = std::move(next);
      const double rate = scene.physics_rate_hz;
      scene = organ->scene;
      if (new_scene) {
        for (const auto& [id, inst] : instruments)
          if (inst.owner != 0) released.emplace_back(id, inst.owner);
        instruments = std::move(made);
        state = State::at_rest(*organ->mesh);
        if (old) ++generation;
      } else {
        scene.physics_rate_hz = rate;  // a set_physics_rate outlives a material change
        if (state.memory.size() != organ->model->memory_size()) state.memory.clear();  // relaxed
      }
      publish_snapshot();
    }
    for (const auto& [id, owner] : released)
      event(proto::EventKind::instrument_released, id, owner, "the scene was replaced by " + scene.name);
    if (new_scene) {
      if (mesh_publisher) {
        mesh_frames_before += mesh_publisher->frames_published();
        mesh_skipped_before += mesh_publisher->frames_skipped();
      }
      mesh_publisher.reset();
      if (scene.mesh_rate_hz > 0)
        mesh_publisher = std::make_unique<MeshPublisher>(participant, surface_topology(organ->boundary), organ->boundary.nodes, scene.mesh_rate_hz);
    }
    if (old) retiring.push_back(std::async(std::launch::async, [o = std::move(old)]() mutable { o.reset(); }));
    std::erase_if(retiring, [](const std::future<void>& f) { return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready; });
  }

  static Eigen::Quaterniond orientation(const proto::Command& c) {
    return Eigen::Quaterniond(c.orientation[0], c.orientation[1], c.orientation[2], c.orientation[3]).normalized();
  }

  /// Grasped tissue follows the jaws through stiff springs; the tool feels their reaction.
  static void add_grasp(ContactResult& result, const GraspHold::Reaction& r) {
    result.force_on_tool += r.force_on_tool;
    result.torque_on_tool += r.torque_on_tool;
    result.in_contact = true;
  }

  /// The instruments' forces on the organ (the integrator's force field, taken implicitly):
  /// contact of each active tool, and the springs holding grasped nodes to the jaws.
  void apply_instruments(const BoundaryConditions::FieldEvaluation& e) {
    for (auto& [id, inst] : instruments) {
      if (!inst.active) {
        inst.result = {};
        continue;
      }
      inst.result = inst.contact->apply(inst.proxy, inst.proxy_velocity, e);
      if (!inst.grasped.empty()) add_grasp(inst.result, inst.grasped.apply(inst.proxy, orientation(inst.tick), inst.proxy_velocity, e));
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

  void publish_scene() {
    proto::Scene sc;
    sc.name = scene.name;
    sc.physics_rate_hz = scene.physics_rate_hz;
    sc.paused = paused;
    {
      std::lock_guard lock(command_mutex);
      for (const auto& [id, inst] : instruments) sc.instruments.push_back({id, inst.spec.kind == InstrumentKind::grasper, inst.spec.tip_radius_m, inst.owner});
    }
    const Box& bounds = organ->bounds;
    sc.bounds_min = {bounds.lo.x(), bounds.lo.y(), bounds.lo.z()};
    sc.bounds_max = {bounds.hi.x(), bounds.hi.y(), bounds.hi.z()};
    sc.generation = generation;
    sc.material = organ->material_info();
    sc.available_scenes = scenes.loadable;
    for (const auto& [name, error] : scenes.unreadable) sc.unreadable_scenes.push_back(name + ": " + error.substr(0, 300));
    if (preparing) sc.preparing = preparing->what;
    sc.recent_requests.assign(outcomes.begin(), outcomes.end());
    scene_state.write(0, proto::encode(sc));
  }

  /// Session requests (physics thread): claim and release an instrument (its owner only);
  /// pause, resume and reset the organ (any client: an instructor's console or a trainer).
  void take_sessions(const std::function<void(const std::string&)>& status) {
    bool changed = false;
    sessions.take([&](const proto::Received& r) {
      std::string why;
      const auto req = proto::decode_session_request(r.payload, &why);
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
        default:
          break;
      }
      // The scene state lists the instruments and their owners: a client sees there at once that
      // an instrument does not exist or is taken (Client::claim says which).
      std::lock_guard lock(command_mutex);
      const auto it = instruments.find(req->instrument_id);
      if (it == instruments.end()) {
        ++rejected_unknown_instrument;
        return;
      }
      Instrument& inst = it->second;
      if (req->action == proto::Action::claim_instrument) {
        if (inst.owner == 0) {
          inst.owner = req->client_id;
          inst.has_command = false;
          inst.last_heard_ns = proto::now_ns();
          changed = true;
          event(proto::EventKind::instrument_claimed, req->instrument_id, req->client_id);
        }  // a claim of a taken instrument is no fault: its owner may let it go
      } else if (inst.owner == req->client_id) {
        inst.owner = 0;
        inst.has_command = false;
        changed = true;
        event(proto::EventKind::instrument_released, req->instrument_id, req->client_id, "released by its owner");
      } else {
        ++rejected_not_owner;
      }
    });
    if (changed) publish_scene();
  }



  /// Run-time control (physics thread): a new physics rate at once; a scene or material is
  /// prepared in the background (finish_preparing() swaps it in). Every request gets an outcome
  /// in the scene state and an event; a refusal says why.
  void control(const proto::SessionRequest& req, const std::function<void(const std::string&)>& status) {
    const auto refuse = [&](const std::string& why) { conclude(req, false, why, status); };
    if (req.action == proto::Action::set_physics_rate) {
      // Whole hertz, as in scene files: the tick grid's period is 1/rate.
      if (req.physics_rate_hz != std::floor(req.physics_rate_hz))
        return refuse("physics rate " + short_number(req.physics_rate_hz) + " Hz: whole hertz only");
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
    if (preparing) return refuse("busy: still preparing " + preparing->what);
    if (req.action == proto::Action::load_scene) {
      const std::string path = (std::filesystem::path(scene_dir) / (req.scene_name + ".json")).string();
      if (!std::filesystem::exists(path)) {
        std::string list;
        for (const auto& n : scenes.loadable) list += (list.empty() ? "" : ", ") + n;
        return refuse("no scene '" + req.scene_name + "' in " + scene_dir + " (available: " + list + ")");
      }
      SceneSpec spec;
      try {
        spec = read_scene_file(path);
      } catch (const std::exception& e) {
        return refuse(e.what());
      }
      if (spec.domain_id != scene.domain_id) spec.domain_id = scene.domain_id;  // the server stays on its domain
      preparing = Preparing{std::async(std::launch::async, [spec, b = budget] { return std::shared_ptr<Organ>(build_organ(spec, b)); }), req,
                            "scene " + req.scene_name};
    } else {
      // The current organ stays alive for the build (shared), even if the server stops meanwhile.
      preparing = Preparing{std::async(std::launch::async, [current = organ, change = req.material, rate = scene.physics_rate_hz, b = budget] {
                              return std::shared_ptr<Organ>(rebuild_with_material(*current, change, rate, b));
                            }),
                            req, "material " + describe_change(req.material)};
    }
    if (status) status("client " + std::to_string(req.client_id) + " asked for " + preparing->what + "; preparing it");
  }

  static std::string describe_change(const proto::MaterialChange& m) {
    std::string out;
    const auto add = [&](const char* name, const std::optional<double>& v) {
      if (!v) return;
      char b[80];
      std::snprintf(b, sizeof b, "%s%s %.6g", out.empty() ? "" : ", ", name, *v);
      out += b;
    };
    add("youngs_modulus_pa", m.youngs_modulus_pa);
    add("poisson_ratio", m.poisson_ratio);
    add("density_kg_m3", m.density_kg_m3);
    add("shear_q", m.shear_q);
    add("damping_per_s", m.damping_per_s);
    return out;
  }

  /// Physics thread, between ticks: a prepared scene or material that is ready replaces the organ.
  void finish_preparing(const std::function<void(const std::string&)>& status) {
    if (!preparing || preparing->organ.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    Preparing done = std::move(*preparing);
    preparing.reset();
    const bool new_scene = done.request.action == proto::Action::load_scene;
    try {
      adopt(done.organ.get(), new_scene);
    } catch (const std::exception& e) {
      conclude(done.request, false, done.what + ": " + e.what(), status);
      return;
    }
    if (new_scene) scenes = list_scenes(scene_dir);
    conclude(done.request, true, (new_scene ? "loaded " : "changed to ") + done.what + " (" + organ->describe_step(scene.physics_rate_hz) + ")", status);
  }

  /// A control request's outcome: in the scene state (the last 8), as an event, on the console.
  void conclude(const proto::SessionRequest& req, bool accepted, const std::string& message, const std::function<void(const std::string&)>& status) {
    outcomes.push_back({req.client_id, req.request_seq, req.action, accepted, message.substr(0, 1000)});
    while (outcomes.size() > 8) outcomes.pop_front();
    const proto::EventKind kind = !accepted ? proto::EventKind::request_refused
                                  : req.action == proto::Action::load_scene ? proto::EventKind::scene_loaded
                                  : req.action == proto::Action::set_material ? proto::EventKind::material_changed
                                                                               : proto::EventKind::physics_rate_changed;
    event(kind, 0, req.client_id, message.substr(0, 1000));
    if (status) status("client " + std::to_string(req.client_id) + " " + proto::action_name(req.action) + ": " + (accepted ? "" : "refused: ") + message);
    publish_scene();
  }

  void rejected_counts(ServerStats& stats) const {
    stats.rejected_malformed = rejected_malformed;
    stats.rejected_not_owner = rejected_not_owner;
    stats.rejected_unknown_instrument = rejected_unknown_instrument;
    stats.rejected = stats.rejected_malformed + stats.rejected_not_owner + stats.rejected_unknown_instrument;
  }

  void mesh_counts(ServerStats& stats) const {
    stats.mesh_frames = mesh_frames_before + (mesh_publisher ? mesh_publisher->frames_published() : 0);
    stats.mesh_frames_skipped = mesh_skipped_before + (mesh_publisher ? mesh_publisher->frames_skipped() : 0);
  }

  /// A session event for recorders, trainers and consoles (physics thread).
  void event(proto::EventKind kind, std::uint32_t instrument_id, std::uint32_t client_id, std::string text = {}) {
    events.write(0, proto::encode(proto::Event{0, kind, instrument_id, client_id, sim_time_s, proto::now_ns(), std::move(text)}));
  }

  /// The organ back at rest (memory variables relaxed); graspers let go.
  void reset_organ() {
    state = State::at_rest(*organ->mesh);
    for (auto& [id, inst] : instruments) inst.grasped = {};
  }

  /// Tick start (physics thread): which instruments are owned and commanded, with which command.
  void take_tick_commands() {
    std::lock_guard lock(command_mutex);
    for (auto& [id, inst] : instruments) {
      const bool was_active = inst.active;
      inst.active = inst.owner != 0 && inst.has_command;
      inst.tick_owner = inst.owner;
      if (!inst.active) {
        inst.grasped = {};  // released, or its client silent: a grasper lets go
        continue;
      }
      inst.tick = inst.last;
      if (!was_active) {
        inst.proxy = Vec3(inst.tick.tip_position[0], inst.tick.tip_position[1], inst.tick.tip_position[2]);
        inst.proxy_velocity = Vec3::Zero();
      }
    }
  }

  /// Graspers: jaws closing (opening below 0.1 rad) grasp the surface nodes within the grasp
  /// radius of the tip; opening them (above 0.2 rad, hysteresis) releases them.
  void update_grasp(Instrument& inst) {
    if (inst.spec.kind != InstrumentKind::grasper) return;
    const Vec3& tip = inst.proxy;  // the grasped nodes follow the simulated tool
    if (inst.grasped.empty() && inst.tick.jaw_opening < 0.1) {
      inst.grasped = GraspHold(tip, orientation(inst.tick), organ->boundary.nodes, state.x, inst.spec.grasp_radius_m, scene.grasp_stiffness_n_per_m);
      if (!inst.grasped.empty())
        event(proto::EventKind::grasped, inst.spec.id, inst.tick_owner, std::to_string(inst.grasped.size()) + " surface nodes");
    } else if (!inst.grasped.empty() && inst.tick.jaw_opening > 0.2) {
      inst.grasped = {};
      event(proto::EventKind::let_go, inst.spec.id, inst.tick_owner);
    }
  }

  /// Each simulated tool moves toward its commanded tip by at most the speed limit times dt;
  /// graspers then close on or let go of the tissue.
  void move_tools(double dt_s) {
    const double reach = scene.max_tool_speed_m_s * dt_s;
    for (auto& [id, inst] : instruments) {
      if (!inst.active) continue;
      const auto& p = inst.tick.tip_position;
      const Vec3 gap = Vec3(p[0], p[1], p[2]) - inst.proxy;
      const double d = gap.norm();
      const Vec3 move = d <= reach ? gap : Vec3((reach / d) * gap);
      inst.proxy += move;
      inst.proxy_velocity = move / dt_s;
      update_grasp(inst);
    }
  }

  /// A client that died or went silent for longer than the lease loses its instrument, which is
  /// released safely (no force on the tissue from it any more).
  void release_silent(std::int64_t lease_ns, const std::function<void(const std::string&)>& status) {
    const std::int64_t now = proto::now_ns();
    std::vector<std::pair<std::uint32_t, std::uint32_t>> released;  // instrument, its silent owner
    {
      std::lock_guard lock(command_mutex);
      for (auto& [id, inst] : instruments)
        if (inst.owner != 0 && now - inst.last_heard_ns > lease_ns) {
          released.emplace_back(id, inst.owner);
          inst.owner = 0;  // its grasper lets go at the next tick (take_tick_commands)
          inst.has_command = false;
        }
    }
    for (const auto& [id, owner] : released) {
      if (status) status("instrument " + std::to_string(id) + " released: client " + std::to_string(owner) + " silent for more than the lease");
      event(proto::EventKind::instrument_released, id, owner, "owner silent for more than the lease");
    }
    if (!released.empty()) publish_scene();
  }

  /// Command thread: each valid command from an instrument's owner becomes the instrument's
  /// newest command and is answered at once with the reaction at the commanded pose on the
  /// newest snapshot (contact query, no step). The next tick steps the tissue with it.
  void answer_new_commands() {
    struct Update {
      std::uint32_t id, owner;
      proto::Command command;
    };
    std::vector<Update> updated;
    std::lock_guard world(organ_mutex);  // the organ and instruments stay while we answer
    commands.take([&](const proto::Received& r) {
      std::string why;
      const auto c = proto::decode_command(r.payload, &why);
      if (!c) {
        ++rejected_malformed;
        return;
      }
      std::lock_guard lock(command_mutex);
      const auto it = instruments.find(c->instrument_id);
      if (it == instruments.end()) {
        ++rejected_unknown_instrument;
        return;
      }
      if (it->second.owner != c->client_id) {
        ++rejected_not_owner;
        return;
      }
      Instrument& inst = it->second;
      inst.last_heard_ns = proto::now_ns();
      if (!inst.has_command || c->seq > inst.last.seq) {
        inst.last = *c;
        inst.has_command = true;
        updated.push_back({c->instrument_id, inst.owner, *c});
      }
    });
    if (updated.empty()) return;
    const auto snap = latest_snapshot();
    for (const auto& u : updated) {
      const auto& p = u.command.tip_position;
      const Vec3 tip(p[0], p[1], p[2]);
      ContactResult result = instruments.at(u.id).query->query(tip, snap->x);
      if (const auto g = snap->grasped.find(u.id); g != snap->grasped.end() && !g->second.empty())
        add_grasp(result, g->second.query(tip, orientation(u.command), snap->x));
      publish_force(u.id, u.owner, u.command, result, 0);
    }
  }

  void publish_force(std::uint32_t id, std::uint32_t owner, const proto::Command& command, const ContactResult& r, std::int64_t step_time_ns) {
    proto::Force f;
    f.instrument_id = id;
    f.client_id = owner;
    f.command_seq = command.seq;
    f.command_client_stamp_ns = command.client_stamp_ns;
    f.server_stamp_ns = proto::now_ns();
    f.step_time_ns = step_time_ns;
    f.force = {r.force_on_tool.x(), r.force_on_tool.y(), r.force_on_tool.z()};
    f.torque = {r.torque_on_tool.x(), r.torque_on_tool.y(), r.torque_on_tool.z()};
    f.in_contact = r.in_contact;
    f.contact_point = {r.point.x(), r.point.y(), r.point.z()};
    f.contact_normal = {r.normal.x(), r.normal.y(), r.normal.z()};
    f.stiffness = local_stiffness(r);
    f.penetration_m = r.depth_m;
    forces.write(id, proto::encode(f));
    ++forces_sent;
  }

  /// After a tick (physics thread): the command thread answers from this state from now on.
  void publish_snapshot() {
    auto snap = std::make_shared<Snapshot>();
    snap->x = state.x;
    for (const auto& [id, inst] : instruments)
      if (!inst.grasped.empty()) snap->grasped[id] = inst.grasped;
    std::lock_guard lock(snapshot_mutex);
    snapshot = std::move(snap);
  }

  /// The local force model's stiffness: the contact penalty in series with the tissue condensed
  /// onto the contact, along the contact normal (the contact is frictionless); the penalty alone
  /// (an upper bound) until the tissue's compliance at the contact is known.
  std::array<double, 9> local_stiffness(const ContactResult& r) {
    if (!r.in_contact || r.deepest_triangle[0] < 0) return r.stiffness;
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> penalty(r.stiffness.data());
    const double k_penalty = r.normal.dot(penalty * r.normal);
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const auto block = organ->compliance->node(r.deepest_triangle[k]);
      if (!block) return r.stiffness;
      C += r.deepest_weights[k] * *block;
    }
    const double k = 1.0 / (1.0 / k_penalty + r.normal.dot(C * r.normal));
    std::array<double, 9> out;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out[3 * i + j] = k * r.normal[i] * r.normal[j];
    return out;
  }

  void publish_forces(std::int64_t step_time_ns) {
    for (auto& [id, inst] : instruments) {
      if (inst.active) publish_force(id, inst.tick_owner, inst.tick, inst.result, step_time_ns);
      // Contact events with hysteresis: a tool that bounces on the surface (a few ms apart) is one
      // contact; it ends after 50 ms of simulated time without touching, or when the tool is gone.
      const bool touching = inst.active && inst.result.in_contact;
      if (touching) {
        if (!inst.touching) event(proto::EventKind::contact_started, id, inst.tick_owner);
        inst.touching = true;
        inst.last_touch_s = sim_time_s;
      } else if (inst.touching && (!inst.active || sim_time_s - inst.last_touch_s > 0.05)) {
        event(proto::EventKind::contact_ended, id, inst.tick_owner);
        inst.touching = false;
      }
    }
  }
};

SimulationServer::SimulationServer(const SceneSpec& scene, const std::string& scene_dir, const TickBudget& budget)
    : impl_(std::make_unique<Impl>(scene, !scene_dir.empty() ? scene_dir
                                          : std::filesystem::path(scene.source).has_parent_path() ? std::filesystem::path(scene.source).parent_path().string()
                                                                                                  : std::string("."),
                                          budget)) {}
SimulationServer::~SimulationServer() = default;

int SimulationServer::abandoned_work() { return g_abandoned.load(); }

std::string SimulationServer::describe() const {
  char b[400];
  std::snprintf(b, sizeof b, "scene %s: %zu nodes, %zu tets, model %s, %zu instruments, %.0f Hz, DDS domain %u, ",
                impl_->scene.name.c_str(), impl_->organ->mesh->node_count(), impl_->organ->mesh->tet_count(),
                std::string(impl_->organ->model->name()).c_str(), impl_->instruments.size(), impl_->scene.physics_rate_hz, impl_->scene.domain_id);
  return b + impl_->organ->describe_step(impl_->scene.physics_rate_hz);
}

ServerStats SimulationServer::run(const std::atomic<bool>& stop, double duration_s, const std::function<void(const std::string&)>& status) {
  Impl& s = *impl_;
  s.stop = &stop;
  ServerStats stats;
  using clock = std::chrono::steady_clock;
  // The command thread answers commands as they arrive, on the other core, while this thread steps.
  std::atomic<bool> stopping{false};
  std::thread command_thread([&] {
    pthread_setname_np(pthread_self(), "command");
    while (!stopping.load())
      if (s.commands.wait(std::chrono::milliseconds(20))) s.answer_new_commands();
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
  std::vector<double> step_us, jitter_us;
  std::uint64_t ticks_at_report = 0;
  while (!stop.load()) {
    const auto tick_start = clock::now();
    jitter_us.push_back(std::chrono::duration<double, std::micro>(tick_start - next).count());
    s.take_sessions(status);
    s.finish_preparing(status);
    const double dt = 1.0 / s.scene.physics_rate_hz;  // session control may change it
    s.release_silent(500'000'000, status);  // the DDS liveliness lease of the command stream
    s.take_tick_commands();
    const auto t0 = clock::now();
    if (!s.paused) {
      s.move_tools(dt);
      try {
        s.organ->integrator->advance(s.state, dt);
        s.sim_time_s += dt;
      } catch (const SimulationError& e) {
        // Keep serving, but never stay stuck: the same input would fail again from the rolled-back
        // state, so the organ goes back to rest (memory variables relaxed) and graspers let go.
        s.reset_organ();
        ++stats.physics_resets;
        if (status) status(std::string("physics: ") + e.what() + "; organ reset to rest");
        s.event(proto::EventKind::physics_reset, 0, 0, e.what());
      }
    }
    const auto t1 = clock::now();
    step_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    s.publish_snapshot();
    s.publish_forces(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
    if (s.mesh_publisher) s.mesh_publisher->offer(s.state.x, s.sim_time_s, proto::now_ns());
    ++stats.ticks;
    if (t1 - last_report >= std::chrono::seconds(1)) {
      const double seconds = std::chrono::duration<double>(t1 - last_report).count();
      stats.rate_hz = static_cast<double>(stats.ticks - ticks_at_report) / seconds;
      stats.step_p50_us = percentile(step_us, 0.5);
      stats.step_p99_us = percentile(step_us, 0.99);
      stats.step_max_us = *std::max_element(step_us.begin(), step_us.end());
      stats.jitter_p99_us = percentile(jitter_us, 0.99);
      s.rejected_counts(stats);
      s.mesh_counts(stats);
      s.telemetry.write(0, proto::encode(proto::TelemetryReport{proto::now_ns(), stats.ticks, stats.late_ticks, stats.rejected, stats.rate_hz,
                                                                stats.step_p50_us, stats.step_p99_us, stats.step_max_us, stats.jitter_p99_us,
                                                                stats.missed_slots, stats.rejected_malformed, stats.rejected_not_owner,
                                                                stats.rejected_unknown_instrument}));
      if (status) {
        char line[400];
        int owned = 0;
        double fmax = 0;
        for (const auto& [id, inst] : s.instruments) {
          owned += inst.active;
          fmax = std::max(fmax, inst.result.force_on_tool.norm());
        }
        std::snprintf(line, sizeof line, "%.0f Hz physics%s, step p50 %.0f us p99 %.0f us max %.0f us, jitter p99 %.0f us, late ticks %llu, missed slots %llu, "
                      "%d instruments in use, |F| %.3f N, rejected %llu (malformed %llu, not owner %llu, unknown instrument %llu), physics resets %llu, "
                      "mesh frames %llu (%llu skipped)",
                      stats.rate_hz, s.paused ? " (paused)" : "", stats.step_p50_us, stats.step_p99_us, stats.step_max_us, stats.jitter_p99_us,
                      static_cast<unsigned long long>(stats.late_ticks), static_cast<unsigned long long>(stats.missed_slots), owned, fmax, static_cast<unsigned long long>(stats.rejected),
                      static_cast<unsigned long long>(stats.rejected_malformed), static_cast<unsigned long long>(stats.rejected_not_owner),
                      static_cast<unsigned long long>(stats.rejected_unknown_instrument),
                      static_cast<unsigned long long>(stats.physics_resets), static_cast<unsigned long long>(stats.mesh_frames),
                      static_cast<unsigned long long>(stats.mesh_frames_skipped));
        status(line);
      }
      step_us.clear();
      jitter_us.clear();
      last_report = t1;
      ticks_at_report = stats.ticks;
    }
    if (duration_s > 0 && std::chrono::duration<double>(t1 - start).count() >= duration_s) break;
    // A late tick is followed at once in its own slot; slots that passed with no tick are counted
    // missed and skipped, never made up in a burst (tick_grid.hpp).
    const auto now = clock::now();
    next = clock::time_point(grid.tick_ended(now.time_since_epoch(), std::chrono::nanoseconds(static_cast<long long>(1e9 * dt))));
    stats.late_ticks = grid.late_ticks();
    stats.missed_slots = grid.missed_slots();
    if (next > now) {
      // Sleep to shortly before the slot, then wait actively: the scheduler wakes a sleeping
      // thread up to ~150 us late on this VM, which with a 0.9 ms tick (12k liver) makes it late.
      const auto early = next - std::chrono::microseconds(200);
      if (early > now) std::this_thread::sleep_until(early);
      while (clock::now() < next) std::this_thread::yield();
    }
  }
  s.rejected_counts(stats);
  stats.forces_sent = s.forces_sent;
  s.mesh_counts(stats);
  return stats;
}

}  // namespace viscera::runtime
