// What the simulation server publishes: the scene state, the scene files, events, the snapshot the  // SPDX-License-Identifier: Apache-2.0
// command thread answers from, and forces.
#include "viscera/runtime/build_info.hpp"

#include "simulation_server_impl.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;

namespace {
/// The server's version and build: a session re-simulates bit for bit on the same build.
std::string server_build() { return std::string("viscera-server ") + VISCERA_BUILD; }
}  // namespace

void SimulationServer::Impl::publish_scene() {
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
void SimulationServer::Impl::publish_scene_files() {
  proto::SceneFiles f;
  f.generation = generation;
  f.server_version = server_build();
  f.files = organ->sources;
  f.first_tick = loaded.first_tick;
  f.sim_time_s = loaded.sim_time_s;
  const nlohmann::json settings = {{"max_tick_ms", 1e3 * budget.max_tick_s},
                                   {"scene_dir", session.scene_dir()},
                                   {"physics_rate_hz", scene.physics_rate_hz},
                                   {"changes", loaded.changes}};
  f.settings_json = settings.dump();
  endpoints.write_scene_files(proto::encode(f));
}

/// A session event for recorders, trainers and consoles (physics thread), stamped with the tick
/// in progress (the request it concludes, if any).
void SimulationServer::Impl::event(proto::EventKind kind, std::uint32_t instrument_id, std::uint32_t client_id, std::string text,
                                   std::uint64_t request_seq, proto::EventReason reason, std::string scene_name) {
  auto payload = proto::encode(proto::Event{0, kind, instrument_id, client_id, sim_time_s, proto::now_ns(), std::move(text), current_tick(),
                                            request_seq, reason, std::move(scene_name)});
  if (capture)
    capture->events.push_back(std::move(payload));
  else
    endpoints.write_event(payload);
}

/// After tick `tick` (physics thread): the command thread answers from this state from now on.
void SimulationServer::Impl::publish_snapshot(std::uint64_t tick) {
  auto snap = std::make_shared<Snapshot>();
  snap->tick = tick;
  snap->max_edge_strain = organ->integrator->max_edge_strain();
  snap->x = state.x;
  snap->organ_epoch = organ_epoch;
  snap->paused = paused;
  snap->tool_reach_m = scene.max_tool_speed_m_s / scene.physics_rate_hz;
  for (const auto& [id, t] : tools) {
    if (!t.tool.held().empty()) snap->grasped[id] = t.tool.held();
    if (t.tool.pressed_through()) snap->pressed_through.insert(id);
    if (t.tool.cutting() || t.tool.leaving_cut()) snap->in_cut.insert(id);
    if (t.tool.active()) snap->tool_position[id] = t.tool.position();
    if (t.tool.active() && scene.contact_proxy) snap->proxies.emplace(id, t.proxy);
    if (t.result.in_contact) snap->tip_strain[id] = t.result.tip_strain;
  }
  responder.publish(std::move(snap));
}

/// `tick`: the tick that stepped with the command, or whose state answered it; `strain`: the
/// organ's largest edge strain that tick.
void SimulationServer::Impl::publish_force(std::uint32_t id, std::uint32_t owner, const proto::Command& command, const ContactResult& r,
                                           std::int64_t step_time_ns, std::uint64_t tick, double strain, std::uint32_t epoch,
                                           double cut_edge_strain) {
  proto::Force f = force_message(id, owner, command, r, local_stiffness(r, *organ->compliance, lockstep), proto::now_ns(), step_time_ns);
  f.tick = tick;
  f.max_edge_strain = strain;
  f.cut_edge_strain = cut_edge_strain;
  f.organ_epoch = epoch;
  auto payload = proto::encode(f);
  if (capture)
    capture->forces.push_back(std::move(payload));
  else
    endpoints.write_force(id, payload);
  ++counted.forces_sent;
}

/// After a tick: every active tool's force, and its contact and grasp events.
void SimulationServer::Impl::publish_forces(std::int64_t step_time_ns) {
  for (auto& [id, t] : tools) {
    if (t.tool.active())
      publish_force(id, t.tool.owner(), t.tool.command(), t.result, std::max<std::int64_t>(step_time_ns, 1), current_tick(),
                    organ->integrator->max_edge_strain(), organ_epoch, t.cut_edge_strain);
    if (const ToolEvent e = t.tool.update_contact(t.result.in_contact, sim_time_s); e != ToolEvent::none)
      event(e == ToolEvent::contact_started ? proto::EventKind::contact_started : proto::EventKind::contact_ended, id, t.tool.owner());
  }
}

}  // namespace viscera::runtime
