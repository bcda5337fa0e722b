#include "viscera/client/client.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

#include "viscera/common/command_line.hpp"
#include "viscera/common/percentile.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/surface_assembler.hpp"
#include "viscera/protocol/typed_reader.hpp"

namespace viscera::client {

namespace proto = viscera::protocol;

const char* to_string(ServerState s) {
  switch (s) {
    case ServerState::waiting: return "waiting";
    case ServerState::alive: return "alive";
    case ServerState::lost: return "lost";
  }
  return "?";
}

struct Client::Impl {
  proto::Participant participant;
  proto::Writer sessions;
  // Made on the first claim or command: a participant whose DDS Security permissions do not grant
  // instrument commands (a trainer, a recorder's identity) still makes session requests.
  std::unique_ptr<proto::Writer> commands;
  std::once_flag commands_made;  // a claim on one thread and commands on another may both make it
  proto::Writer& command_writer() {
    std::call_once(commands_made, [this] { commands = std::make_unique<proto::Writer>(participant, proto::Stream::instrument_command); });
    return *commands;
  }
  proto::TypedReader<proto::Stream::force_feedback> forces;
  proto::TypedReader<proto::Stream::scene_state> scene;
  std::set<std::uint32_t> claimed;  // instruments this client claimed (another process may run under its id)
  // When each was claimed [DDS time, ns], until the first answer to this client's own commands: a
  // force answering a command stamped before is another process's under this id, never its own.
  std::map<std::uint32_t, std::int64_t> claimed_at_ns;
  std::unique_ptr<proto::TypedReader<proto::Stream::surface_topology>> topology;  // created on first use
  std::unique_ptr<proto::TypedReader<proto::Stream::mesh_frame>> frames;
  std::unique_ptr<proto::TypedReader<proto::Stream::event>> events;
  std::unique_ptr<proto::TypedReader<proto::Stream::telemetry>> telemetry;  // created with the client: its liveliness counts
  proto::Rejections rejections;  // payloads of every stream that failed their decoder
  std::unique_ptr<proto::Writer> annotations;
  std::atomic<bool> sessions_settled{false};
  // Before the first request: every reader of session requests (the server's, a recorder's) knows
  // this writer, or the request is lost to the one that learns of it last (a recording that holds
  // the server's answer to a request but not the request cannot re-run it). False if no reader.
  bool session_readers_known(std::chrono::milliseconds timeout) {
    if (!sessions_settled) sessions_settled = sessions.wait_for_settled_readers(std::chrono::milliseconds(100), timeout);
    return sessions_settled;
  }
  proto::SurfaceAssembler surfaces;  // whole surfaces from whole ones and patches (schema 16)
  // The server's presence, from the DDS liveliness of its writers that this client reads: the
  // scene state (written only on a change), the forces (1 kHz while an instrument is driven) and
  // the telemetry (once a second, always). A server silent for the lease loses the liveliness of
  // all of them; when it speaks again, DDS gives it back writer by writer, as each one writes: its
  // forces at once if an instrument is driven, its telemetry within a second, its scene state only
  // at the next change. So any one alive means the server is there. The telemetry is what brings
  // it back when nothing is driven: after a stall of this client's own (the server heard nothing
  // for its lease and freed the instrument, so no force comes). Set by DDS listener threads.
  std::atomic<int> scene_writers{0}, force_writers{0}, telemetry_writers{0};
  std::atomic<ServerState> server{ServerState::waiting};
  std::atomic<std::int64_t> lost_ns{0};
  std::atomic<bool> server_was_lost{false};  // set on a loss, taken by take_scene()
  std::mutex callback_mutex;
  std::function<void(ServerState)> callback;
  Impl(std::uint32_t domain, const std::string& partition)
      : participant(domain, partition), sessions(participant, proto::Stream::session_request), forces(participant), scene(participant) {
    scene.raw().on_alive_writers_changed([this](int alive) {
      scene_writers = alive;
      liveliness();
    });
    forces.raw().on_alive_writers_changed([this](int alive) {
      force_writers = alive;
      liveliness();
    });
    telemetry = std::make_unique<proto::TypedReader<proto::Stream::telemetry>>(participant);
    telemetry->raw().on_alive_writers_changed([this](int alive) {
      telemetry_writers = alive;
      liveliness();
    });
    scene_writers = scene.alive_writers();  // a server discovered before the listeners were set
    force_writers = forces.alive_writers();
    telemetry_writers = telemetry->alive_writers();
    liveliness();
  }
  void liveliness() {
    std::lock_guard lock(callback_mutex);
    const bool alive = scene_writers.load() + force_writers.load() + telemetry_writers.load() > 0;
    const ServerState before = server.load();
    const ServerState now = alive ? ServerState::alive : before == ServerState::waiting ? ServerState::waiting : ServerState::lost;
    if (now == before) return;
    if (now == ServerState::lost) {
      lost_ns = proto::now_ns();
      server_was_lost = true;
    }
    server = now;
    if (callback) callback(now);
  }

  // The newest scene state, and the participant that wrote it. After a loss it is held back until
  // it is shown to hold: a newer one arrives (a restarted server publishes its own), or a force
  // arrives from the participant that wrote it (the same server, back from a stall, whose scene
  // state has not changed and so is not written again).
  std::optional<proto::Scene> last_scene;
  std::uint64_t scene_from = 0;
  bool scene_unconfirmed = false;
  std::int64_t unconfirmed_since_ns = 0;
  // The newest force from the server (any client's): its sender and its stamp (the sender's clock).
  std::uint64_t force_from = 0;
  std::int64_t force_stamp_ns = 0;
  void take_scene() {
    if (server_was_lost.exchange(false)) {
      scene_unconfirmed = true;
      unconfirmed_since_ns = lost_ns.load();
    }
    scene.take(
        [&](proto::Scene s, const proto::Received& r) {
          last_scene = std::move(s);
          scene_from = r.participant;
          scene_unconfirmed = false;
        },
        rejections);
    if (scene_unconfirmed && server.load() == ServerState::alive && force_from != 0 && force_from == scene_from &&
        force_stamp_ns > unconfirmed_since_ns)
      scene_unconfirmed = false;
  }
  const std::optional<proto::Scene>& current_scene() const {
    static const std::optional<proto::Scene> none;
    return scene_unconfirmed ? none : last_scene;
  }
};

namespace {
/// The participant's settings checked before DDS sees them: what every program's command line
/// refuses, refused here for every client (the Python package's too). A station name of 66,000
/// characters crashed Cyclone in dds_create_writer; '*' reached live servers' partitions.
/// Returns the partition.
const std::string& checked_participant(std::uint32_t domain_id, std::uint32_t client_id, const std::string& partition) {
  if (domain_id > 230) throw common::UsageError("domain " + std::to_string(domain_id) + " is outside [0, 230]");
  if (client_id == 0 || client_id > 4000000000u)
    throw common::UsageError("client id " + std::to_string(client_id) + " is outside [1, 4000000000] (0 is reserved)");
  proto::checked_station(partition, "station");
  return partition;
}
}  // namespace

Client::Client(std::uint32_t domain_id, std::uint32_t client_id, const std::string& partition)
    : impl_(std::make_unique<Impl>(domain_id, checked_participant(domain_id, client_id, partition))), client_id_(client_id) {}
Client::~Client() = default;

std::optional<proto::Scene> Client::wait_for_scene(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    impl_->scene.wait(std::chrono::milliseconds(50));
    if (const auto& s = fresh_scene()) return s;
  }
  return std::nullopt;
}

std::optional<proto::Scene> Client::scene() { return fresh_scene(); }

ClaimResult Client::claim(std::uint32_t instrument_id, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  const proto::SessionRequest r{client_id_, proto::Action::claim_instrument, instrument_id};
  std::string why = "no scene state from the server";
  // Shown as this id's before this client asked for it: another process runs under this client id
  // and holds it. Not asked for (a claim would renew that process's lease) until it lets it go.
  bool another_owner_seen = impl_->claimed.count(instrument_id) > 0;
  impl_->command_writer();  // discovered by the server's reader while the claim goes through
  while (std::chrono::steady_clock::now() < end) {
    if (const auto& s = fresh_scene()) {
      // The scene state lists the instruments and their owners.
      const auto it = std::find_if(s->instruments.begin(), s->instruments.end(), [&](const auto& i) { return i.instrument_id == instrument_id; });
      if (it == s->instruments.end()) {
        std::string list;
        for (const auto& i : s->instruments)
          list += (list.empty() ? "" : ", ") + std::to_string(i.instrument_id) + (i.scalpel ? " (scalpel)" : i.grasper ? " (grasper)" : " (probe)");
        return {false, "scene " + s->name + " has no instrument " + std::to_string(instrument_id) + " (its instruments: " + list + ")"};
      }
      if (it->owner_client_id == client_id_ && !another_owner_seen) {
        why = "instrument " + std::to_string(instrument_id) + " is held under this client id (" + std::to_string(client_id_) +
              ") by another client: two clients must not run with one id";
        impl_->scene.wait(std::chrono::milliseconds(100));
        continue;
      }
      const bool twin_seen = !another_owner_seen && it->owner_client_id == 0 && impl_->claimed.count(instrument_id) == 0 &&
                             why.find("held under this client id") != std::string::npos;
      another_owner_seen = true;
      if (it->owner_client_id == client_id_) {
        impl_->claimed.insert(instrument_id);
        // Forces of a process that held it under this id before (their sequence numbers, higher
        // than this client's, hid every answer to it: a second haptic-client drove the tip to -6 cm
        // with 0 N) are never this client's.
        impl_->claimed_at_ns[instrument_id] = proto::now_ns();
        latest_.erase(instrument_id);
        // Before the first command: every reader of commands (the server's, a recorder's) knows
        // this client's writer, or the first commands are lost to the one that learns of it last.
        impl_->command_writer().wait_for_settled_readers(std::chrono::milliseconds(100), std::chrono::milliseconds(500));
        return {true, {}};
      }
      // Taken: keep asking until the timeout, its owner may release it (or lose it to the lease).
      if (twin_seen || why.find("until just now") != std::string::npos)
        why = "instrument " + std::to_string(instrument_id) + " was held under this client id (" + std::to_string(client_id_) +
              ") by another client until just now, and the server did not confirm the claim (it keeps an id for the process that used "
              "it until that process has been silent for 0.5 s): two clients must not run with one id";
      else
        why = it->owner_client_id != 0 ? "taken by client " + std::to_string(it->owner_client_id) : "the server did not confirm the claim";
    }
    impl_->sessions.write(client_id_, proto::encode(r));
    impl_->scene.wait(std::chrono::milliseconds(100));
  }
  return {false, why};
}

void Client::release(std::uint32_t instrument_id) {
  impl_->claimed.erase(instrument_id);
  impl_->sessions.write(client_id_, proto::encode(proto::SessionRequest{client_id_, proto::Action::release_instrument, instrument_id}));
}

bool Client::control(proto::Action action, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  impl_->session_readers_known(timeout);
  do {
    impl_->sessions.write(client_id_, proto::encode(proto::SessionRequest{client_id_, action, 0}));
    // A reset shows in no state: it is done once the server acknowledged the request.
    if (action == proto::Action::reset) return impl_->sessions.wait_for_acks(timeout);
    impl_->scene.wait(std::chrono::milliseconds(100));
    if (const auto& s = fresh_scene(); s && s->paused == (action == proto::Action::pause)) return true;
  } while (std::chrono::steady_clock::now() < end);
  return false;
}

std::optional<proto::RequestOutcome> Client::request(proto::SessionRequest r, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  if (request_seq_ == 0) request_seq_ = static_cast<std::uint64_t>(proto::now_ns());
  r.client_id = client_id_;
  r.request_seq = ++request_seq_;
  // Refused here, at once, with the server's own reason, what the server would refuse as malformed
  // (and so never answer: the caller would wait its whole timeout).
  std::string why;
  if (!proto::decode_session_request(proto::encode(r), &why)) throw common::UsageError(std::string(proto::action_name(r.action)) + ": " + why);
  // Sent once: a second copy would load the scene twice.
  if (!impl_->session_readers_known(timeout)) return std::nullopt;
  impl_->sessions.write(client_id_, proto::encode(r));
  while (std::chrono::steady_clock::now() < end) {
    impl_->scene.wait(std::chrono::milliseconds(100));
    if (const auto& s = fresh_scene())
      for (const auto& o : s->recent_requests)
        if (o.client_id == client_id_ && o.request_seq == r.request_seq) return o;
  }
  return std::nullopt;
}

std::optional<proto::RequestOutcome> Client::load_scene(const std::string& name, std::chrono::milliseconds timeout,
                                                        std::optional<std::uint64_t> seed) {
  proto::SessionRequest r;
  r.action = proto::Action::load_scene;
  r.scene_name = name;
  r.scene_seed = seed;
  return request(std::move(r), timeout);
}

std::optional<proto::RequestOutcome> Client::set_material(const proto::MaterialChange& change, std::chrono::milliseconds timeout) {
  proto::SessionRequest r;
  r.action = proto::Action::set_material;
  r.material = change;
  return request(std::move(r), timeout);
}

std::optional<proto::RequestOutcome> Client::set_physics_rate(double rate_hz, std::chrono::milliseconds timeout) {
  proto::SessionRequest r;
  r.action = proto::Action::set_physics_rate;
  r.physics_rate_hz = rate_hz;
  return request(std::move(r), timeout);
}

std::optional<proto::RequestOutcome> Client::take_over(std::uint32_t instrument_id, std::chrono::milliseconds timeout) {
  proto::SessionRequest r;
  r.action = proto::Action::take_over;
  r.instrument_id = instrument_id;
  return request(std::move(r), timeout);
}

std::optional<proto::RequestOutcome> Client::hand_back(std::uint32_t instrument_id, std::chrono::milliseconds timeout) {
  proto::SessionRequest r;
  r.action = proto::Action::hand_back;
  r.instrument_id = instrument_id;
  return request(std::move(r), timeout);
}

std::optional<proto::RequestOutcome> Client::seek(double seconds, std::chrono::milliseconds timeout) {
  proto::SessionRequest r;
  r.action = proto::Action::seek;
  r.seek_s = seconds;
  return request(std::move(r), timeout);
}

void Client::send_tip(std::uint32_t instrument_id, const proto::Vector3& tip, double jaw_opening_rad, std::uint32_t buttons) {
  // The server refuses such a command as malformed: its instrument would go silent and be freed.
  if (!std::isfinite(tip[0]) || !std::isfinite(tip[1]) || !std::isfinite(tip[2]) || !std::isfinite(jaw_opening_rad))
    throw std::invalid_argument("send_tip: the tip position or jaw opening is not finite");
  proto::Command c;
  c.instrument_id = instrument_id;
  c.client_id = client_id_;
  c.seq = ++seq_;
  c.client_stamp_ns = proto::now_ns();
  c.tip_position = tip;
  c.jaw_opening = jaw_opening_rad;
  c.buttons = buttons;
  impl_->command_writer().write(instrument_id, proto::encode(c));
}

void Client::take_forces() {
  const std::int64_t now = proto::now_ns();
  impl_->forces.take(
      [&](const proto::Force& f, const proto::Received& r) {
        if (r.stamp_ns >= impl_->force_stamp_ns) {  // any client's force: the server answers
          impl_->force_from = r.participant;
          impl_->force_stamp_ns = r.stamp_ns;
        }
        if (f.client_id != client_id_) return;
        // Until the first answer to this client's own commands after a claim, those to commands
        // stamped before it are another process's under this id (only until then: a step of the
        // wall clock later must not hide this client's answers).
        if (const auto c = impl_->claimed_at_ns.find(f.instrument_id); c != impl_->claimed_at_ns.end()) {
          if (f.command_client_stamp_ns < c->second) return;
          impl_->claimed_at_ns.erase(c);
        }
        if (f.step_time_ns > 0) {  // published after a tick (the immediate answers carry 0)
          auto& end = tick_end_ns_[f.instrument_id];
          end = std::max(end, f.server_stamp_ns);
        }
        auto& slot = latest_[f.instrument_id];
        if (f.command_seq >= slot.command_seq) {
          if (f.command_seq > slot.command_seq) rtt_us_.push_back(1e-3 * static_cast<double>(now - f.command_client_stamp_ns));
          slot = f;
        }
      },
      impl_->rejections);
}

std::optional<proto::Force> Client::poll_force(std::uint32_t instrument_id) {
  take_forces();
  const auto it = latest_.find(instrument_id);
  if (it == latest_.end()) return std::nullopt;
  return it->second;
}

const std::optional<proto::Scene>& Client::fresh_scene() {
  take_forces();  // a force from the scene state's writer confirms it after a loss
  impl_->take_scene();
  return impl_->current_scene();
}

std::optional<std::int64_t> Client::last_tick_end_ns(std::uint32_t instrument_id) const {
  const auto it = tick_end_ns_.find(instrument_id);
  if (it == tick_end_ns_.end()) return std::nullopt;
  return it->second;
}

std::optional<proto::Force> Client::wait_force(std::uint32_t instrument_id, std::chrono::steady_clock::time_point deadline) {
  for (;;) {
    auto f = poll_force(instrument_id);
    if (f && f->command_seq == seq_) return f;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return f;
    impl_->forces.wait(deadline - now);
  }
}

std::optional<proto::SurfaceTopology> Client::surface() {
  if (!impl_->topology) {
    impl_->topology = std::make_unique<proto::TypedReader<proto::Stream::surface_topology>>(impl_->participant);
    impl_->frames = std::make_unique<proto::TypedReader<proto::Stream::mesh_frame>>(impl_->participant);
  }
  impl_->topology->take([&](const proto::SurfaceTopology& t, const proto::Received&) { impl_->surfaces.take(t); }, impl_->rejections);
  return impl_->surfaces.surface();
}

std::optional<proto::MeshFrame> Client::poll_mesh_frame() {
  const auto topology = surface();
  std::optional<proto::MeshFrame> newest;
  impl_->frames->take(
      [&](proto::MeshFrame f, const proto::Received&) {
        if (!topology || f.mesh_id > topology->mesh_id) return;  // its topology (transient local) is still on its way
        // A cut changes the surface: a frame of a later generation waits for its topology, one of
        // an earlier generation is old news.
        if (f.mesh_id == topology->mesh_id && f.topology_generation != topology->topology_generation) return;
        if (f.mesh_id != topology->mesh_id || f.positions.size() != 3ull * topology->vertex_count) {
          impl_->rejections.add("mesh_frame: " + std::to_string(f.positions.size() / 3) + " vertices for mesh " + std::to_string(f.mesh_id) +
                                ", whose topology has " + std::to_string(topology->vertex_count) + " (mesh " + std::to_string(topology->mesh_id) +
                                ")");
          return;
        }
        ++mesh_frames_;
        if (!newest || f.frame > newest->frame) newest = std::move(f);
      },
      impl_->rejections);
  return newest;
}

std::vector<proto::Event> Client::poll_events() {
  if (!impl_->events) impl_->events = std::make_unique<proto::TypedReader<proto::Stream::event>>(impl_->participant);
  std::vector<proto::Event> out;
  impl_->events->take([&](proto::Event e, const proto::Received&) { out.push_back(std::move(e)); }, impl_->rejections);
  return out;
}

std::vector<proto::TelemetryReport> Client::poll_telemetry() {
  std::vector<proto::TelemetryReport> out;
  impl_->telemetry->take([&](proto::TelemetryReport t, const proto::Received&) { out.push_back(t); }, impl_->rejections);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.server_stamp_ns < b.server_stamp_ns; });
  return out;
}

std::uint64_t Client::rejected() const { return impl_->rejections.count; }
std::string Client::last_rejection() const { return impl_->rejections.last_reason; }

void Client::annotate(const std::string& text) {
  if (text.size() > 1024) throw std::invalid_argument("annotation of " + std::to_string(text.size()) + " bytes (at most 1024)");
  if (!impl_->annotations) {
    impl_->annotations = std::make_unique<proto::Writer>(impl_->participant, proto::Stream::event);
    // A new writer's first sample reaches only the readers discovered by then.
    impl_->annotations->wait_for_settled_readers(std::chrono::milliseconds(100), std::chrono::seconds(1));
  }
  impl_->annotations->write(client_id_,
                            proto::encode(proto::Event{client_id_, proto::EventKind::annotation, 0, client_id_, 0, proto::now_ns(), text}));
  impl_->annotations->wait_for_acks(std::chrono::seconds(1));
}

std::int64_t now_ns() { return proto::now_ns(); }

ServerState Client::server_state() const { return impl_->server.load(); }

std::optional<std::int64_t> Client::server_lost_ns() const {
  const std::int64_t t = impl_->lost_ns.load();
  if (t == 0) return std::nullopt;
  return t;
}

void Client::on_server_state(std::function<void(ServerState)> f) {
  std::lock_guard lock(impl_->callback_mutex);
  impl_->callback = std::move(f);
}

LatencyStats Client::round_trip() const {
  LatencyStats s;
  s.samples = rtt_us_.size();
  if (rtt_us_.empty()) return s;
  s.p50_us = common::percentile(rtt_us_, 0.5);
  s.p99_us = common::percentile(rtt_us_, 0.99);
  s.max_us = *std::max_element(rtt_us_.begin(), rtt_us_.end());
  return s;
}

}  // namespace viscera::client
