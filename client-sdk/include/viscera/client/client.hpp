#pragma once  // SPDX-License-Identifier: Apache-2.0
// viscera's client SDK: find a server's scene, claim an instrument, stream poses, receive forces,
// measure the command-to-force round trip. Built on protocol/ (the only DDS wrapper).
//
//   viscera::client::Client c(domain, client_id);
//   auto scene = c.wait_for_scene(std::chrono::seconds(5));
//   if (c.claim(1, std::chrono::seconds(2))) { c.send_tip(1, {x, y, z}); auto f = c.poll_force(1); }
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viscera/protocol/messages.hpp"

namespace viscera::client {

/// Whether a server is there: none seen yet; its writers alive; or gone (stopped, killed, stalled,
/// or its host cut off: its DDS liveliness lease of 500 ms ran out, or it left the domain). A
/// stalled server that speaks again is alive again.
enum class ServerState { waiting, alive, lost };
const char* to_string(ServerState s);

/// The protocol's clock [ns]: DDS's time, the wall clock (since the Unix epoch; not monotonic, a
/// clock step moves it). The stamps of commands and forces are on it: a round trip on one host is
/// two readings of it; across hosts the clocks must be synchronised (docs/DEPLOY.md).
std::int64_t now_ns();

/// What became of a claim.
struct ClaimResult {
  bool claimed = false;
  std::string why;  ///< when not claimed: the server's reason (no such instrument, taken), or the timeout
  explicit operator bool() const { return claimed; }
};

struct LatencyStats {
  std::size_t samples = 0;
  double p50_us = 0, p99_us = 0, max_us = 0;
};

/// One client of a server: one DDS participant under one client id (the server binds the id to
/// that participant for what acts on instruments). Calls are made from one thread, except that one
/// thread may send tips (send_tip) while another makes requests (the console does).
class Client {
 public:
  /// `partition`: the DDS partition to work in ("" : the default, where live servers are; a replay
  /// publishes in a partition of its own, viscera-replay play --station).
  Client(std::uint32_t domain_id, std::uint32_t client_id, const std::string& partition = {});
  ~Client();

  /// Waits for the server's scene state (published reliably, transient local).
  std::optional<protocol::Scene> wait_for_scene(std::chrono::milliseconds timeout);
  /// The newest scene state received, without waiting (none once the server was lost, until a
  /// server publishes one again).
  std::optional<protocol::Scene> scene();
  /// Claims an instrument: claimed once the scene state shows this client as its owner; refused at
  /// once with the server's reason if the scene has no such instrument or another client owns it.
  /// An instrument the scene shows as this client id's before this client claimed it is held by
  /// another process under the same id: not claimed (two clients must not run with one id) until
  /// that one lets it go or loses it to the lease.
  ClaimResult claim(std::uint32_t instrument_id, std::chrono::milliseconds timeout);
  void release(std::uint32_t instrument_id);
  /// Session control for the whole scene (any client, e.g. an instructor's console): pause,
  /// resume or reset. True once the scene state shows the pause state asked for (for reset:
  /// once the server acknowledged the request).
  bool control(protocol::Action action, std::chrono::milliseconds timeout);
  /// Run-time control (any client): load a scene of the server's scene directory by name, change
  /// material parameters (the organ keeps its deformation), or change the physics rate [Hz].
  /// Sends the request once (reliably) and waits up to `timeout` for the server's outcome, which
  /// says what was done or why not; nothing if no outcome came in time. Loading a scene releases
  /// every instrument: their owners claim again (Scene::generation tells them it happened).
  /// `seed`: the seed of the scene's drawn material regions (none: the scene file's).
  std::optional<protocol::RequestOutcome> load_scene(const std::string& name, std::chrono::milliseconds timeout,
                                                     std::optional<std::uint64_t> seed = std::nullopt);
  std::optional<protocol::RequestOutcome> set_material(const protocol::MaterialChange& change, std::chrono::milliseconds timeout);
  std::optional<protocol::RequestOutcome> set_physics_rate(double rate_hz, std::chrono::milliseconds timeout);
  /// An instructor's console: take an instrument from its owner at once (the server moves the
  /// ownership in one step, never leaving it free; a free instrument is claimed), and hand it back
  /// to the client it was taken from. Keep commanding it in between: an owner silent for the
  /// liveliness lease loses it. The outcome says what was done or why not.
  std::optional<protocol::RequestOutcome> take_over(std::uint32_t instrument_id, std::chrono::milliseconds timeout);
  std::optional<protocol::RequestOutcome> hand_back(std::uint32_t instrument_id, std::chrono::milliseconds timeout);
  /// A replay (viscera-replay play, in its partition): jump to `seconds` from the recording's start.
  /// A live server refuses it.
  std::optional<protocol::RequestOutcome> seek(double seconds, std::chrono::milliseconds timeout);
  /// Sends the instrument's tip position [m] and jaw opening [rad] (next sequence number,
  /// current stamp).
  /// `buttons`: the device's buttons as a bit mask (bit 0, button 1: a mark, docs/TRAINING.md).
  void send_tip(std::uint32_t instrument_id, const protocol::Vector3& tip, double jaw_opening_rad = 0.5, std::uint32_t buttons = 0);
  /// Takes the forces that arrived; returns the newest for the instrument, if any. Each one
  /// whose echoed stamp is this client's adds a round-trip sample.
  std::optional<protocol::Force> poll_force(std::uint32_t instrument_id);
  /// Waits (at most until `deadline`) for a force answering the newest command of the
  /// instrument; returns the newest force seen either way.
  std::optional<protocol::Force> wait_force(std::uint32_t instrument_id, std::chrono::steady_clock::time_point deadline);
  LatencyStats round_trip() const;
  /// When the server ended the newest tick whose force for this instrument has been taken (its
  /// stamp, DDS time [ns]), for keeping a loop in phase with the physics (tick_phase.hpp).
  std::optional<std::int64_t> last_tick_end_ns(std::uint32_t instrument_id) const;

  /// The organ's boundary surface (triangles, rest positions), once it has arrived: the newest,
  /// which changes when the organ is cut (its topology_generation). The first call subscribes
  /// this client to the mesh streams; clients that never call it receive none.
  std::optional<protocol::SurfaceTopology> surface();
  /// The newest surface frame that arrived since the last call, checked against the topology
  /// (frames of another mesh_id or with another vertex count are dropped and counted; frames of
  /// another topology generation, a cut on its way, are dropped silently).
  std::optional<protocol::MeshFrame> poll_mesh_frame();
  std::uint64_t mesh_frames_received() const { return mesh_frames_; }

  /// Session events (server) and annotations (clients) that arrived since the last call, in
  /// order. The first call subscribes; events before it are not seen.
  std::vector<protocol::Event> poll_events();
  /// The server's health reports (about one a second: achieved physics rate, step times, tick
  /// jitter, ticks run, late ticks, missed slots, rejected messages) that arrived since the last
  /// call, oldest first. The first call subscribes; reports before it are not seen. Best effort,
  /// keep last 1: a client that polls less than once a second sees only the newest.
  std::vector<protocol::TelemetryReport> poll_telemetry();
  /// Publishes an annotation (at most 1024 bytes of text) for recorders and consoles. The first
  /// call waits (up to 1 s) for a reader to be discovered; each waits (up to 1 s) for the readers'
  /// acknowledgements, so a client that exits right after still delivers it.
  void annotate(const std::string& text);
  std::uint32_t id() const { return client_id_; }
  /// Whether the server is there: the DDS liveliness of its writers this client reads (the scene
  /// state and the forces). A server silent for the lease (500 ms) is lost; when it speaks again
  /// it is alive again, and its last scene state holds once a force of its own confirms it.
  ServerState server_state() const;
  /// When the server was last seen going (now_ns clock), if it was.
  std::optional<std::int64_t> server_lost_ns() const;
  /// Calls `f` on a DDS thread each time server_state() changes. Keep it short (set a flag).
  void on_server_state(std::function<void(ServerState)> f);
  /// Payloads that failed verification and were dropped.
  std::uint64_t rejected() const;
  /// Why the newest of them was ("force_feedback: force: not finite"); "" if none was.
  std::string last_rejection() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::uint32_t client_id_;
  std::optional<protocol::RequestOutcome> request(protocol::SessionRequest r, std::chrono::milliseconds timeout);
  /// Takes the forces that arrived (every client's: each one is a sign of the server).
  void take_forces();
  /// The newest scene state that is known to hold (none after a loss until it is confirmed).
  const std::optional<protocol::Scene>& fresh_scene();

  std::uint64_t seq_ = 0, mesh_frames_ = 0;
  std::uint64_t request_seq_ = 0;  // starts at the clock: a restarted client never matches its old outcomes
  std::vector<double> rtt_us_;
  std::map<std::uint32_t, protocol::Force> latest_;
  std::map<std::uint32_t, std::int64_t> tick_end_ns_;  // per instrument: the newest tick force's stamp
};

}  // namespace viscera::client
