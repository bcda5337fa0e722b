// The simulation server's organ and its tick, and the two loops that run it: at a fixed rate on  // SPDX-License-Identifier: Apache-2.0
// the wall clock with a command thread beside it (run), or step by step from a lockstep driver
// (run_lockstep). What it publishes, the commands and the session requests are in files of their
// own (simulation_server_impl.hpp).
#include "viscera/runtime/simulation_server.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include <pthread.h>

#include "viscera/runtime/organ_cutting.hpp"
#include "viscera/runtime/surface_exit.hpp"
#include "viscera/runtime/tick_grid.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

#include "simulation_server_impl.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;
using Status = std::function<void(const std::string&)>;

SimulationServer::Impl::Impl(const SceneSpec& s, ServerEndpoints& e, std::string dir, const TickBudget& b, bool lockstep_mode)
    : scene(s),
      endpoints(e),
      budget(b),
      lockstep(lockstep_mode),
      session(
          std::move(dir), [b](const SceneSpec& spec) { return std::shared_ptr<Organ>(build_organ(spec, b)); },
          [b](const std::shared_ptr<const Organ>& current, const proto::MaterialChange& change, double rate_hz) {
            return std::shared_ptr<Organ>(rebuild_with_material(*current, change, rate_hz, b));
          }),
      clients(std::chrono::nanoseconds(proto::kLivelinessLease).count(), e.authenticated()) {
  adopt(build_organ(s, budget), true);
  publish_scene();
  publish_scene_files();
}

/// Physics thread, between ticks: `next` becomes the organ. A new scene starts at rest with its
/// own instruments (owners lose theirs and must claim again) and a new surface; a new material
/// on the same mesh keeps the organ's deformation, its owners and its tools.
void SimulationServer::Impl::adopt(std::shared_ptr<Organ> next, bool new_scene) {
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
                                    std::make_unique<ProbeContact>(organ->contact_surface, spec.tip_radius_m, scene.contact_stiffness_n_per_m, 0.02,
                                                                   scene.contact_damping_s_per_m),
                                    ContactProxy(organ->contact_surface, proxy_parameters(scene, spec)),
                                    {},
                                    {},
                                    0,
                                    {}});
      responder.set_instruments(scene.instruments, organ->contact_surface, scene.contact_stiffness_n_per_m);
      strokes = 0;
      topology_to_publish = false;
      state = State::at_rest(*organ->mesh);
      reserve_for_cuts(*organ, state);
      if (old) ++generation;
      loaded.first_tick = current_tick();
      loaded.sim_time_s = sim_time_s;
      loaded.changes = nlohmann::json::array();
    } else {
      scene.physics_rate_hz = rate;  // a set_physics_rate outlives a material change
      if (state.memory.size() != organ->model->memory_size()) state.memory.clear();  // relaxed
      for (auto& [id, t] : tools)  // a stiffer material under a pressing tool: it enters again
        if (t.tool.active()) start_outside(t);
    }
    if (old) ++organ_epoch;
    publish_snapshot(ticks_run);
  }
  for (const auto& o : released)
    event(proto::EventKind::instrument_released, o.instrument_id, o.owner, "the scene was replaced by " + scene.name, 0,
          proto::EventReason::scene_replaced);
  if (new_scene && !lockstep) {
    if (mesh_publisher) {
      mesh_frames_before += mesh_publisher->frames_published();
      mesh_skipped_before += mesh_publisher->frames_skipped();
    }
    mesh_publisher.reset();
    if (scene.mesh_rate_hz > 0)
      mesh_publisher =
          std::make_unique<MeshPublisher>(endpoints.open_mesh_stream(), surface_topology(organ->boundary), organ->boundary.nodes, scene.mesh_rate_hz);
  }
  session.retire(std::move(old));
}

/// The organ back at rest (memory variables relaxed); graspers let go.
void SimulationServer::Impl::reset_organ() {
  state = State::at_rest(*organ->mesh);
  reserve_for_cuts(*organ, state);
  ++organ_epoch;
  for (auto& [id, t] : tools) {
    t.tool.let_go();
    if (t.tool.active()) start_outside(t);
  }
}

void SimulationServer::Impl::start_outside(Tool& t) const {
  t.proxy.release();  // it anchors again where the tool enters
  // Out the way it came: along the normal of the contact it had (a reset or a new material under a
  // press), else up against gravity (scenes' gravity is along -z), the way a hand brings a tool.
  const Vec3 back = t.result.in_contact ? t.result.normal : Vec3::UnitZ();
  if (const auto out = way_out(*organ->contact_surface, state.x, t.tool.position(), back, t.tool.spec().tip_radius_m)) t.tool.withdraw(*out);
  const BoundaryConditions::FieldEvaluation look{.x = state.x, .v = {}, .f = {}, .stiffness = {}, .damping = {}, .dt_s = 0.0};
  for (int k = 0; k < 4; ++k) {  // the contact's normal is the touched triangles' mean: a few passes
    const ContactResult r = t.contact->apply(t.tool.position(), Vec3::Zero(), look);
    if (!r.in_contact) return;
    t.tool.withdraw(r.depth_m * r.normal);
  }
}

void SimulationServer::Impl::leave_cuts() {
  for (auto& [id, t] : tools)
    if (t.tool.leaving_cut() && !t.contact->query(t.tool.position(), state.x).in_contact &&
        !inside_surface(*organ->contact_surface, state.x, t.tool.position()))
      t.tool.clear_of_tissue();
}

/// The instruments' forces on the organ (the integrator's force field, taken implicitly):
/// contact of each active tool, and the springs holding grasped nodes to the jaws.
void SimulationServer::Impl::apply_instruments(const BoundaryConditions::FieldEvaluation& e) {
  for (auto& [id, t] : tools) {
    if (!t.tool.active() || t.tool.cutting() || t.tool.leaving_cut()) {  // a cutting blade passes through the tissue
      t.result = ContactResult{.cutting = t.tool.cutting()};
      continue;
    }
    t.result =
        scene.contact_proxy ? t.proxy.apply(t.tool.position(), t.tool.velocity(), e) : t.contact->apply(t.tool.position(), t.tool.velocity(), e);
    if (!t.tool.held().empty()) add_grasp(t.result, t.tool.held().apply(t.tool.position(), t.tool.orientation(), t.tool.velocity(), e));
  }
}

/// After the step: the tissue's strain about each instrument that touches it, averaged over the
/// scene's strain radius around the point it touches in the rest shape (the deepest contact's, or
/// the grasped nodes' mean), over 20 ms windows (TipStrainWindow).
void SimulationServer::Impl::measure_tip_strain() {
  const auto& rest = organ->mesh->nodes;
  const std::size_t window = tip_strain_window_ticks(scene.physics_rate_hz);
  for (auto& [id, t] : tools) {
    ContactResult& r = t.result;
    std::optional<Vec3> at;
    if (r.in_contact && r.deepest_triangle[0] >= 0) {
      at = Vec3::Zero();
      for (int k = 0; k < 3; ++k) *at += r.deepest_weights[k] * rest[static_cast<std::size_t>(r.deepest_triangle[static_cast<std::size_t>(k)])];
    } else if (r.in_contact && !t.tool.held().empty()) {
      at = t.tool.held().mean_of(rest);
    }
    r.tip_strain = t.tip_strain.after_tick(*organ->strain, state.x, at, window);
  }
}

/// The boundary surface with its vertices numbered in the order of boundary.nodes.
proto::SurfaceTopology SimulationServer::Impl::surface_topology(const BoundarySurface& boundary) const {
  return whole_surface(generation, organ->topology_generation, scene.name, *organ->mesh, boundary);
}

/// Session requests, a finished build, the lease; then the organ stepped by 1/rate with each
/// owned instrument's newest command; then the snapshot, the forces and a surface frame.
/// Returns the step's duration [ns].
/// In lockstep (`step`), the requests and commands are the step's, and no lease runs out.
std::int64_t SimulationServer::Impl::tick(const Status& status, const proto::LockstepStep* step) {
  take_sessions(status, step);
  finish_preparing(status);
  const double dt = 1.0 / scene.physics_rate_hz;  // session control may change it
  if (step)
    command_in_lockstep(step->commands);
  else
    release_silent(status);
  for (const TickCommand& c : instruments.tick_commands())
    if (Tool& t = tools.at(c.instrument_id); t.tool.begin_tick(c.active, c.owner, c.command)) start_outside(t);
  const auto t0 = std::chrono::steady_clock::now();
  if (!paused) {
    for (auto& [id, t] : tools) {
      t.tool.move(dt, scene.max_tool_speed_m_s);
      if (scene.contact_proxy && t.tool.active() && !t.tool.cutting() && !t.tool.leaving_cut())
        t.proxy.track(t.tool.position(), state.x, dt);
      else
        t.proxy.release();
      if (const ToolEvent e = t.tool.update_grasp(organ->boundary.nodes, state.x, scene.grasp_stiffness_n_per_m); e == ToolEvent::grasped)
        event(proto::EventKind::grasped, id, t.tool.owner(), std::to_string(t.tool.held().size()) + " surface nodes");
      else if (e == ToolEvent::let_go)
        event(proto::EventKind::let_go, id, t.tool.owner());
    }
    try {
      organ->integrator->advance(state, dt);
      sim_time_s += dt;
      cut_with_scalpels(status);
      leave_cuts();
      measure_tip_strain();
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
  if (mesh_publisher) {
    const std::int64_t now = proto::now_ns();
    if (topology_to_publish && mesh_publisher->due(now)) {  // at most one topology per frame
      mesh_publisher->change_topology(surface_topology(organ->boundary), organ->boundary.nodes);
      topology_to_publish = false;
    }
    mesh_publisher->offer(state.x, sim_time_s, now, current_tick());
  }
  ++ticks_run;
  ++stats.ticks;
  return step_ns;
}

/// The surface after the last tick, as the mesh publisher sends it.
std::vector<std::uint8_t> SimulationServer::Impl::surface_frame() const {
  proto::MeshFrame f;
  f.mesh_id = generation;
  f.frame = ticks_run;
  f.sim_time_s = sim_time_s;
  f.server_stamp_ns = proto::now_ns();
  f.tick = ticks_run;
  f.topology_generation = organ->topology_generation;
  f.positions.resize(3 * organ->boundary.nodes.size());
  copy_surface(state.x, organ->boundary.nodes, f.positions.data());
  return proto::encode(f);
}

/// Lockstep: one step from the driver, and its result.
proto::LockstepResult SimulationServer::Impl::lockstep_tick(const proto::LockstepStep& step, bool first, const Status& status) {
  proto::LockstepResult result;
  result.tick = step.tick;
  if (first) {  // the recording's clock: its tick numbers and simulated time
    ticks_run = step.tick - 1;
    sim_time_s = step.sim_time_s;
    loaded.first_tick = step.tick;
    loaded.sim_time_s = sim_time_s;
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
void SimulationServer::Impl::collect_counts() {
  stats.rejected_malformed = counted.malformed;
  stats.rejected_not_owner = counted.not_owner;
  stats.rejected_unknown_instrument = counted.unknown_instrument;
  stats.rejected_other_participant = counted.other_participant;
  stats.rejected = stats.rejected_malformed + stats.rejected_not_owner + stats.rejected_unknown_instrument + stats.rejected_other_participant;
  stats.forces_sent = counted.forces_sent;
  stats.mesh_frames = mesh_frames_before + (mesh_publisher ? mesh_publisher->frames_published() : 0);
  stats.mesh_frames_skipped = mesh_skipped_before + (mesh_publisher ? mesh_publisher->frames_skipped() : 0);
}

std::string SimulationServer::Impl::status_now() const {
  int in_use = 0;
  double fmax = 0, strain = 0;
  for (const auto& [id, t] : tools) {
    in_use += t.tool.active();
    fmax = std::max(fmax, t.result.force_on_tool.norm());
    if (t.result.in_contact && std::isfinite(t.result.tip_strain)) strain = std::max(strain, t.result.tip_strain);
  }
  return status_line(stats, paused, in_use, fmax, strain);
}

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
        ++s.counted.malformed;
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
      // Stamped when its counts were taken (the end of this tick), not when it is written: a stall
      // between the two (a busy machine) made a report's ticks and missed slots lag its stamp by
      // 15 ms, and the slots of the grid between two reports no longer added up.
      const std::int64_t counted_ns = proto::now_ns();
      statistics.close_window(std::chrono::duration<double>(t1 - last_report).count(), s.stats);
      s.collect_counts();
      s.endpoints.write_telemetry(proto::encode(telemetry_report(s.stats, counted_ns)));
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
