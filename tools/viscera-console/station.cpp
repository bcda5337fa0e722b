#include "station.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <chrono>
#include <map>

#include "viscera/client/client.hpp"
#include "viscera/client/stream_tap.hpp"
#include "viscera/console/console_wire.hpp"
#include "viscera/console/force_decimator.hpp"
#include "viscera/console/foxglove_protocol.hpp"
#include "viscera/protocol/streams.hpp"
#include "viscera/protocol/surface_assembler.hpp"

namespace viscera::console {

namespace proto = viscera::protocol;

std::shared_ptr<const std::string> Station::tagged(nlohmann::json j) const {
  j["station"] = name_;
  return std::make_shared<const std::string>(j.dump());
}

Station::Station(std::uint32_t domain, std::string partition, std::uint32_t client_id, double force_period_s, StationSink sink)
    : domain_(domain),
      partition_(std::move(partition)),
      name_(partition_.empty() ? "default" : partition_),
      client_id_(client_id),
      force_period_s_(force_period_s),
      sink_(std::move(sink)) {
  // One participant for the requests and the taken-over instruments' commands: the server binds
  // the console's client id to the participant that acts on instruments under it.
  client_ = std::make_unique<client::Client>(domain_, client_id_, partition_);
  streams_ = std::thread([this] { stream_loop(); });
  worker_ = std::thread([this] { request_loop(); });
  driver_ = std::thread([this] { drive_loop(); });
}

Station::~Station() {
  stop_ = true;
  requests_cv_.notify_all();
  streams_.join();
  worker_.join();
  driver_.join();
}

StationSnapshot Station::snapshot() const {
  const std::lock_guard lock(mutex_);
  return snapshot_;
}

void Station::stream_loop() {
  // The page's streams, and every stream a session has for Foxglove clients.
  const std::vector<proto::Stream>& streams = foxglove_streams();
  client::StreamTap tap(domain_, partition_, streams, 256);
  ForceDecimator forces(force_period_s_);
  std::map<std::uint32_t, proto::Vector3> tips;
  std::uint32_t mesh_id = 0, vertex_count = 0, topology_generation = 0;
  proto::SurfaceAssembler surfaces;  // whole surfaces from the server's patches (schema 16)
  const auto now_s = [] { return 1e-9 * static_cast<double>(client::now_ns()); };
  while (!stop_) {
    tap.wait(std::chrono::milliseconds(5));
    const bool raw = sink_.wants_raw && sink_.wants_raw();
    tap.take([&](const client::TapSample& s) {
      // The state streams always (the bridge keeps their newest for Foxglove clients that come later).
      // The surface goes on whole (below): a client that comes later gets the whole one.
      const bool state = proto::stream_info(s.stream).state;
      if ((raw || state) && s.stream != proto::Stream::surface_topology)
        sink_.raw(s.stream, s.stamp_ns, std::make_shared<const std::vector<std::uint8_t>>(s.payload.begin(), s.payload.end()));
      std::string why;
      switch (s.stream) {
        case proto::Stream::instrument_command:
          if (const auto c = proto::decode_command(s.payload, &why)) {
            tips[c->instrument_id] = c->tip_position;
            const std::lock_guard lock(mutex_);
            tips_[c->instrument_id] = c->tip_position;
          }
          break;
        case proto::Stream::force_feedback:
          if (const auto f = proto::decode_force(s.payload, &why)) forces.add(*f);
          break;
        case proto::Stream::scene_state:
          if (const auto sc = proto::decode_scene(s.payload, &why)) {
            auto m = tagged(to_json(*sc));
            {
              const std::lock_guard lock(mutex_);
              snapshot_.scene = m;
              bounds_min_ = sc->bounds_min;
              bounds_max_ = sc->bounds_max;
              // An instrument the console no longer owns (a scene loaded, its lease lost) is not driven.
              for (auto it = held_.begin(); it != held_.end();) {
                const auto i =
                    std::find_if(sc->instruments.begin(), sc->instruments.end(), [&](const auto& x) { return x.instrument_id == it->first; });
                it = (i == sc->instruments.end() || i->owner_client_id != client_id_) ? held_.erase(it) : std::next(it);
              }
            }
            sink_.message({m, false, false});
          }
          break;
        case proto::Stream::telemetry:
          if (const auto t = proto::decode_telemetry(s.payload, &why)) {
            auto m = tagged(to_json(*t));
            {
              const std::lock_guard lock(mutex_);
              snapshot_.telemetry = m;
            }
            sink_.message({m, false, true});
          }
          break;
        case proto::Stream::surface_topology:
          if (const auto message = proto::decode_surface_topology(s.payload, &why); message && surfaces.take(*message)) {
            const proto::SurfaceTopology* t = &*surfaces.surface();
            sink_.raw(s.stream, s.stamp_ns, std::make_shared<const std::vector<std::uint8_t>>(proto::encode(*t)));
            mesh_id = t->mesh_id;
            vertex_count = t->vertex_count;
            topology_generation = t->topology_generation;
            auto m = std::make_shared<const std::string>(encode_topology(*t));
            {
              const std::lock_guard lock(mutex_);
              snapshot_.topology = m;
              snapshot_.frame = nullptr;
            }
            sink_.message({m, true, false});
          }
          break;
        case proto::Stream::mesh_frame:
          if (const auto f = proto::decode_mesh_frame(s.payload, &why)) {
            // A frame of another surface than the topology's (a scene being swapped, a cut whose
            // topology is still on its way) waits for its own.
            if (f->mesh_id != mesh_id || f->topology_generation != topology_generation || f->positions.size() != 3 * std::size_t{vertex_count}) break;
            auto m = std::make_shared<const std::string>(encode_frame(*f, 1e-6 * static_cast<double>(f->server_stamp_ns)));
            {
              const std::lock_guard lock(mutex_);
              snapshot_.frame = m;
              frame_delays_ms_.push_back(1e-6 * static_cast<double>(client::now_ns() - f->server_stamp_ns));
              if (frame_delays_ms_.size() > 1000) frame_delays_ms_.pop_front();
            }
            sink_.frame(m);
          }
          break;
        case proto::Stream::event:
          if (const auto e = proto::decode_event(s.payload, &why)) sink_.message({tagged(to_json(*e)), false, false});
          break;
        default: break;
      }
      if (!why.empty()) ++rejected_;
    });
    const auto summaries = forces.flush(now_s());
    if (!summaries.empty()) sink_.message({tagged(forces_json(summaries, {tips.begin(), tips.end()})), false, true});
  }
}

bool Station::request(const BrowserRequest& r, std::function<void(nlohmann::json)> reply) {
  {
    const std::lock_guard lock(mutex_);
    if (requests_.size() >= 32) return false;
    requests_.emplace_back(r, std::move(reply));
  }
  requests_cv_.notify_one();
  return true;
}

std::pair<double, double> Station::frame_delay_ms() const {
  std::vector<double> d;
  {
    const std::lock_guard lock(mutex_);
    d.assign(frame_delays_ms_.begin(), frame_delays_ms_.end());
  }
  if (d.empty()) return {0, 0};
  std::sort(d.begin(), d.end());
  return {d[d.size() / 2], d[std::min(d.size() - 1, d.size() * 99 / 100)]};
}

bool Station::move(std::uint32_t instrument, const proto::Vector3& delta, std::string* why) {
  const std::lock_guard lock(mutex_);
  const auto it = held_.find(instrument);
  if (it == held_.end()) {
    *why = "move: instrument " + std::to_string(instrument) + " is not taken over by this console";
    return false;
  }
  for (int k = 0; k < 3; ++k) it->second[k] = std::clamp(it->second[k] + delta[k], bounds_min_[k] - 0.05, bounds_max_[k] + 0.05);
  return true;
}

void Station::drive_loop() {
  client::Client& driver = *client_;
  auto next = std::chrono::steady_clock::now();
  while (!stop_) {
    std::map<std::uint32_t, proto::Vector3> held;
    {
      const std::lock_guard lock(mutex_);
      held = held_;
    }
    for (const auto& [id, tip] : held) driver.send_tip(id, tip);
    next += std::chrono::milliseconds(5);
    std::this_thread::sleep_until(next);
  }
}

void Station::request_loop() {
  client::Client& client = *client_;
  while (true) {
    std::pair<BrowserRequest, std::function<void(nlohmann::json)>> job;
    {
      std::unique_lock lock(mutex_);
      requests_cv_.wait(lock, [&] { return stop_ || !requests_.empty(); });
      if (stop_) return;
      job = std::move(requests_.front());
      requests_.pop_front();
    }
    const BrowserRequest& r = job.first;
    nlohmann::json out = {{"type", "reply"}, {"id", r.id}, {"request", request_type_name(r.type)}, {"station", name_}};
    const auto done = [&](bool ok, const std::string& message) {
      out["ok"] = ok;
      out["message"] = message;
    };
    const auto outcome = [&](const std::optional<proto::RequestOutcome>& o) {
      if (!o)
        done(false, "no answer from the server in time");
      else
        done(o->accepted, o->message);
    };
    using namespace std::chrono_literals;
    switch (r.type) {
      case RequestType::pause:
      case RequestType::resume:
      case RequestType::reset: {
        const auto action = r.type == RequestType::pause    ? proto::Action::pause
                            : r.type == RequestType::resume ? proto::Action::resume
                                                            : proto::Action::reset;
        const bool ok = client.control(action, 5s);
        done(ok, ok ? std::string(proto::action_name(action)) + ": done" : "no confirmation from the server in 5 s");
        break;
      }
      case RequestType::load_scene: outcome(client.load_scene(r.text, 60s, r.seed)); break;
      case RequestType::material: outcome(client.set_material(r.change, 60s)); break;
      case RequestType::annotate:
        client.annotate(r.text);
        done(true, "annotated");
        break;
      case RequestType::bookmark:
        client.annotate("bookmark" + (r.text.empty() ? std::string() : ": " + r.text));
        done(true, "bookmarked");
        break;
      case RequestType::take_over: {
        // Driven from where its owner left it (above the organ if it was never commanded), from
        // before the request: the server keeps that pose until the console's first command.
        {
          const std::lock_guard lock(mutex_);
          const auto t = tips_.find(r.instrument);
          held_[r.instrument] =
              t != tips_.end() ? t->second
                               : proto::Vector3{(bounds_min_[0] + bounds_max_[0]) / 2, (bounds_min_[1] + bounds_max_[1]) / 2, bounds_max_[2] + 0.02};
        }
        const auto o = client.take_over(r.instrument, 5s);
        outcome(o);
        if (!o || !o->accepted) {
          const std::lock_guard lock(mutex_);
          held_.erase(r.instrument);
        }
        break;
      }
      case RequestType::hand_back: {
        const auto o = client.hand_back(r.instrument, 5s);
        outcome(o);
        if (o && o->accepted) {
          const std::lock_guard lock(mutex_);
          held_.erase(r.instrument);
        }
        break;
      }
      case RequestType::move:  // carried out at once (move())
      case RequestType::watch: done(true, "watching " + name_); break;
      case RequestType::recordings:
      case RequestType::open_recording: done(false, "not a station's request (the web server answers it)"); break;
    }
    job.second(std::move(out));
  }
}

}  // namespace viscera::console
