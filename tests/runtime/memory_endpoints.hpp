#pragma once  // SPDX-License-Identifier: Apache-2.0
// The server's endpoints in memory instead of DDS, for tests of the whole server in one process:
// the test pushes commands, requests and lockstep steps; the server's writes are kept.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/server_endpoints.hpp"
#include "viscera/runtime/simulation_server.hpp"

namespace viscera::runtime::testing {

namespace proto = viscera::protocol;

/// Endpoints in memory: the test pushes commands and requests, the server's writes are kept.
class MemoryEndpoints final : public ServerEndpoints {
 public:
  struct Mesh final : MeshStream {
    explicit Mesh(MemoryEndpoints& e) : e_(e) {}
    void write_topology(std::uint32_t, std::span<const std::uint8_t>) override { ++e_.topologies; }
    void write_frame(std::uint32_t, std::span<const std::uint8_t>) override { ++e_.frames; }
    MemoryEndpoints& e_;
  };

  /// `participant`: the sending DDS participant (Received::participant), one unless a test says.
  void push_command(const proto::Command& c, std::uint64_t participant = 1) { push(commands_, proto::encode(c), participant); }
  void push_request(const proto::SessionRequest& r, std::uint64_t participant = 1) { push(sessions_, proto::encode(r), participant); }

  int take_commands(const Take& f) override { return take(commands_, f); }
  bool wait_commands(std::chrono::nanoseconds timeout) override {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return !commands_.empty(); });
  }
  int take_session_requests(const Take& f) override { return take(sessions_, f); }
  void write_force(std::uint32_t, std::span<const std::uint8_t> p) override { keep(forces, p); }
  void write_scene(std::span<const std::uint8_t> p) override { keep(scenes, p); }
  void write_telemetry(std::span<const std::uint8_t> p) override { keep(telemetry, p); }
  void write_event(std::span<const std::uint8_t> p) override { keep(events, p); }
  void write_scene_files(std::span<const std::uint8_t> p) override { keep(scene_files, p); }
  std::unique_ptr<MeshStream> open_mesh_stream() override { return std::make_unique<Mesh>(*this); }

  template <class Decoded, class Decode>
  std::vector<Decoded> decoded(const std::vector<std::vector<std::uint8_t>>& kept, Decode decode) {
    std::lock_guard lock(mutex_);
    std::vector<Decoded> out;
    std::string why;
    for (const auto& p : kept)
      if (auto d = decode(p, &why)) out.push_back(*d);
    return out;
  }

  std::vector<std::vector<std::uint8_t>> forces, scenes, telemetry, events, scene_files;
  std::atomic<int> topologies{0}, frames{0};

 private:
  using Sent = std::pair<std::vector<std::uint8_t>, std::uint64_t>;  // payload, participant
  void push(std::deque<Sent>& q, std::vector<std::uint8_t> p, std::uint64_t participant) {
    {
      std::lock_guard lock(mutex_);
      q.emplace_back(std::move(p), participant);
    }
    cv_.notify_all();
  }
  int take(std::deque<Sent>& q, const Take& f) {
    std::deque<Sent> taken;
    {
      std::lock_guard lock(mutex_);
      taken.swap(q);
    }
    std::uint64_t seq = 0;
    for (const auto& [p, participant] : taken) f({1, ++seq, 0, p, participant, participant});
    return static_cast<int>(taken.size());
  }
  void keep(std::vector<std::vector<std::uint8_t>>& v, std::span<const std::uint8_t> p) {
    std::lock_guard lock(mutex_);
    v.emplace_back(p.begin(), p.end());
  }
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Sent> commands_, sessions_;
};

/// A lockstep driver in memory: steps pushed, results kept.
class MemoryLockstepLink final : public LockstepLink {
 public:
  void push_step(const proto::LockstepStep& s) {
    {
      std::lock_guard lock(mutex_);
      steps_.push_back(proto::encode(s));
    }
    cv_.notify_all();
  }
  int take_steps(std::chrono::nanoseconds timeout, const std::function<void(std::span<const std::uint8_t>)>& f) override {
    std::deque<std::vector<std::uint8_t>> taken;
    {
      std::unique_lock lock(mutex_);
      cv_.wait_for(lock, timeout, [&] { return !steps_.empty(); });
      taken.swap(steps_);
    }
    for (const auto& s : taken) f(s);
    return static_cast<int>(taken.size());
  }
  void write_result(std::span<const std::uint8_t> p) override {
    std::string why;
    auto r = proto::decode_lockstep_result(p, &why);
    std::lock_guard lock(mutex_);
    results_.push_back(r ? *r : proto::LockstepResult{0, 0, {}, {}, {}, "undecodable result: " + why});
    cv_.notify_all();
  }
  /// Waits until `n` results are in (or the timeout passes); returns them.
  std::vector<proto::LockstepResult> wait_results(std::size_t n, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, timeout, [&] { return results_.size() >= n; });
    return results_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::vector<std::uint8_t>> steps_;
  std::vector<proto::LockstepResult> results_;
};

/// The whole server in one process on endpoints in memory, stepping in real time on a thread of
/// its own from construction until stop() (or destruction).
struct LiveServer {
  explicit LiveServer(const std::string& scene_file)
      : scene(read_scene_file(scene_file)), server(scene, endpoints), physics([this] { stats = server.run(stopping, 0, {}); }) {}
  ~LiveServer() { stop(); }
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;
  /// Stops the physics thread; the run's statistics.
  const ServerStats& stop() {
    if (physics.joinable()) {
      stopping = true;
      physics.join();
    }
    return stats;
  }

  SceneSpec scene;
  MemoryEndpoints endpoints;
  SimulationServer server;
  std::atomic<bool> stopping{false};
  ServerStats stats;
  std::thread physics;  // last: started once the rest exists
};

}  // namespace viscera::runtime::testing
