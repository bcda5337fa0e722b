#pragma once  // SPDX-License-Identifier: Apache-2.0
// The simulation server's state and the work of its threads (private to server/runtime): the
// organ and the tick (simulation_server.cpp), what the server publishes (server_publishing.cpp),
// the commands the command thread answers (command_handling.cpp), and the session requests the
// physics thread takes between ticks (session_requests.cpp).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/client_binding.hpp"
#include "viscera/runtime/command_responder.hpp"
#include "viscera/runtime/instrument_table.hpp"
#include "viscera/runtime/mesh_publisher.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/session_control.hpp"
#include "viscera/runtime/simulated_tool.hpp"
#include "viscera/runtime/simulation_server.hpp"
#include "viscera/runtime/tip_strain_window.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/integrator/state.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::runtime {

namespace proto = viscera::protocol;

struct SimulationServer::Impl {
  using Status = std::function<void(const std::string&)>;

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
  tissue::State state;
  double sim_time_s = 0;
  std::uint64_t ticks_run = 0;  // physics thread; the tick in progress (or the next) is ticks_run + 1
  std::uint32_t generation = 1;  // +1 per scene loaded: the surface's mesh_id
  bool paused = false;
  // physics thread: +1 at each reset, scene loaded, material changed, pause and resume (the forces'
  // organ_epoch: a client fades its force in again when it changes)
  std::uint32_t organ_epoch = 0;
  // What the scene was loaded with and changed by since (SceneFiles, for recordings).
  struct SceneRecord {
    std::uint64_t first_tick = 1;
    double sim_time_s = 0;
    nlohmann::json changes = nlohmann::json::array();  // the material and rate requests since
  } loaded;
  // Lockstep (run_lockstep): no wall clock, no lease, builds waited for; forces and events of the
  // tick go into its result.
  bool lockstep = false;
  proto::LockstepResult* capture = nullptr;

  InstrumentTable instruments;  // both threads (thread-safe)
  struct Stroke {  // a scalpel's cut in progress
    std::int32_t id = -1;  // -1: not cutting
    tissue::Vec3 blade_tip = tissue::Vec3::Zero(), blade_end = tissue::Vec3::Zero();  // the blade after the last tick
    std::size_t sweeps = 0, tets_cut = 0, split_edges = 0, duplicated_nodes = 0, changes = 0, energy_rises = 0;
    double added_mass_kg = 0, energy_change_max_j = 0;
  };
  struct Tool {  // physics thread only
    SimulatedTool tool;
    std::unique_ptr<ProbeContact> contact;  // the tip's sphere against the surface: where it enters
    ContactProxy proxy;  // the tool the tissue touches (its force)
    ContactResult result;
    Stroke stroke;
    double cut_edge_strain = 0;  // the largest edge strain of what its blade cut this tick
    TipStrainWindow tip_strain;  // the strain at it, over 20 ms windows
  };
  std::map<std::uint32_t, Tool> tools;
  std::int32_t strokes = 0;  // physics thread: strokes begun on this organ (the next one's id)
  bool topology_to_publish = false;  // physics thread: the surface changed since the mesh publisher last had it
  CommandResponder responder;
  SessionControl session;
  std::unique_ptr<MeshPublisher> mesh_publisher;  // its own thread
  std::uint64_t mesh_frames_before = 0, mesh_skipped_before = 0;  // of the publishers of earlier scenes
  struct Counted {  // both threads: refused commands and requests by reason, forces sent
    std::atomic<std::uint64_t> malformed{0}, not_owner{0}, unknown_instrument{0}, other_participant{0}, forces_sent{0};
  } counted;
  ClientBinding clients;  // both threads (thread-safe)
  ServerStats stats;  // physics thread

  Impl(const SceneSpec& s, ServerEndpoints& e, std::string dir, const TickBudget& b, bool lockstep_mode);

  /// The tick in progress, or between ticks the next one.
  std::uint64_t current_tick() const { return ticks_run + 1; }

  // --- The organ
  /// Physics thread, between ticks: `next` becomes the organ. A new scene starts at rest with its
  /// own instruments (owners lose theirs and must claim again) and a new surface; a new material
  /// on the same mesh keeps the organ's deformation, its owners and its tools.
  void adopt(std::shared_ptr<Organ> next, bool new_scene);

  /// The organ back at rest (memory variables relaxed); graspers let go, and a tool the rest
  /// shape now holds inside starts on its surface again.
  void reset_organ();

  /// A tool that appears inside the tissue (claimed there, or held there while the organ went back
  /// to rest, was replaced or changed its material) is withdrawn to the surface above its tip and
  /// enters at the scene's speed limit: placed at full depth in one tick, the contact's whole force
  /// would strike a few surface nodes in one step (on the 12k liver, a probe claimed 2 cm deep
  /// reset the organ 17 times a second). At any depth: a tip deeper than the contact's depth limit
  /// leaves through the nearest surface point (surface_exit.hpp).
  void start_outside(Tool& t) const;

  /// The instruments' forces on the organ (the integrator's force field, taken implicitly):
  /// contact of each active tool, and the springs holding grasped nodes to the jaws.
  void apply_instruments(const tissue::BoundaryConditions::FieldEvaluation& e);

  /// After the step: the tissue's strain at each instrument that touches it (ContactResult::tip_strain).
  void measure_tip_strain();

  /// The boundary surface with its vertices numbered in the order of boundary.nodes.
  proto::SurfaceTopology surface_topology(const tissue::BoundarySurface& boundary) const;

  /// After the step: every scalpel whose owner holds its cut button cuts the organ with the surface
  /// its blade swept during the tick, and strokes begin and end with events. The contacts see the
  /// cut surface from the next tick on.
  void cut_with_scalpels(const Status& status);
  /// After the step: a scalpel leaving a cut (its button released in the tissue) touches again
  /// once neither its tip's contact nor the surface holds it inside.
  void leave_cuts();
  /// A scalpel's stroke ends (its cut_ended event says what it cut).
  void end_stroke(std::uint32_t id, Tool& t);
  /// Between strokes, the haptic local model's contact compliance of the cut organ: built again in
  /// the background once the organ's cuts are not the ones it has seen (rebuild_compliance), and
  /// swapped in once ready. One that cannot be factorised (a piece cut free) leaves the one in use.
  void refresh_compliance(const Status& status);

  // --- What the server publishes
  void publish_scene();

  /// What it takes to re-run the scene (recordings): its files, the server's build and settings,
  /// the material and rate changes since it was loaded, its first tick.
  void publish_scene_files();

  /// A session event for recorders, trainers and consoles (physics thread), stamped with the tick
  /// in progress (the request it concludes, if any).
  void event(proto::EventKind kind, std::uint32_t instrument_id, std::uint32_t client_id, std::string text = {}, std::uint64_t request_seq = 0,
             proto::EventReason reason = proto::EventReason::unspecified, std::string scene_name = {});

  /// After tick `tick` (physics thread): the command thread answers from this state from now on.
  void publish_snapshot(std::uint64_t tick);

  /// `tick`: the tick that stepped with the command, or whose state answered it; `strain`: the
  /// organ's largest edge strain that tick; `epoch`: the organ's epoch then; `cut_edge_strain`: a
  /// scalpel's, of what it cut that tick.
  void publish_force(std::uint32_t id, std::uint32_t owner, const proto::Command& command, const ContactResult& r, std::int64_t step_time_ns,
                     std::uint64_t tick, double strain, std::uint32_t epoch, double cut_edge_strain = 0);

  /// After a tick: every active tool's force, and its contact and grasp events.
  void publish_forces(std::int64_t step_time_ns);

  // --- Commands (command thread)
  /// A command's payload decoded, or counted as malformed.
  std::optional<proto::Command> decode_counted(std::span<const std::uint8_t> payload);

  /// A command offered to its instrument, a refusal counted; whether it became the newest.
  bool offer_counted(const proto::Command& c, std::int64_t now_ns);

  /// Each valid command from an instrument's owner becomes the instrument's newest command and is
  /// answered at once with the reaction at the commanded pose on the newest snapshot (contact
  /// query, no step). The next tick steps the tissue with it.
  void answer_new_commands();

  /// Lockstep: the step's answers, on the state the previous tick left (as the command thread
  /// answers them live); they do not become the instruments' commands. Ownership is not checked
  /// again: the live server answered them, so their client owned the instrument then, and a claim
  /// or release in the same step may have come before or after them live (the order of the two
  /// within one tick's interval is not recorded).
  void answer_in_lockstep(const std::vector<std::vector<std::uint8_t>>& answers);

  /// Lockstep: the step's commands become their instruments' newest (the live command thread's
  /// other half).
  void command_in_lockstep(const std::vector<std::vector<std::uint8_t>>& commands);

  // --- Session requests (physics thread)
  /// Claim and release an instrument (its owner only); pause, resume and reset the organ, load a
  /// scene, change the material or the physics rate (any client: an instructor's console or a
  /// trainer).
  void take_sessions(const Status& status, const proto::LockstepStep* step);

  /// Run-time control: a new physics rate at once; a scene or material is prepared in the
  /// background (finish_preparing() swaps it in). Every request gets an outcome in the scene state
  /// and an event; a refusal says why.
  /// True when it concluded the request (and so published the scene state).
  bool control(const proto::SessionRequest& req, const Status& status);

  /// Physics thread, between ticks: a prepared scene or material that is ready replaces the organ
  /// (in lockstep, once it is ready: the tick that asked for it uses it).
  void finish_preparing(const Status& status);

  /// An instructor takes an instrument over from its owner, or hands it back: ownership moves in
  /// one step (never free in between), with an event naming both clients and an outcome.
  void hand_over(const proto::SessionRequest& req, const Status& status);

  /// A control request's outcome: in the scene state (the last 8), as an event, on the console.
  void conclude(const proto::SessionRequest& req, bool accepted, const std::string& message, const Status& status);

  /// A client that died or went silent for longer than the lease loses its instrument, which is
  /// released safely (no force on the tissue from it any more).
  void release_silent(const Status& status);
  std::int64_t last_silence_check_ns = 0;  // release_silent's previous check (DDS time [ns]; 0: none yet)

  // --- One tick (physics thread)
  /// Session requests, a finished build, the lease; then the organ stepped by 1/rate with each
  /// owned instrument's newest command; then the snapshot, the forces and a surface frame.
  /// Returns the step's duration [ns].
  /// In lockstep (`step`), the requests and commands are the step's, and no lease runs out.
  std::int64_t tick(const Status& status, const proto::LockstepStep* step = nullptr);

  /// The surface after the last tick, as the mesh publisher sends it.
  std::vector<std::uint8_t> surface_frame() const;

  /// Lockstep: one step from the driver, and its result.
  proto::LockstepResult lockstep_tick(const proto::LockstepStep& step, bool first, const Status& status);

  /// The counters the other threads keep, into stats.
  void collect_counts();

  std::string status_now() const;
};

}  // namespace viscera::runtime
