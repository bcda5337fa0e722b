#include "viscera/runtime/parallel_forces.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

#include <sched.h>

#include "viscera/tissue/mesh/locality_order.hpp"

namespace viscera::runtime {

using tissue::ElementPart;
using tissue::ForceStats;
using tissue::Vec3;

ParallelForces::ParallelForces(const tissue::ForceModel& model, int threads, int chunks) : model_(model), chunks_(static_cast<std::size_t>(chunks)) {
  if (threads < 1 || chunks < threads) throw std::invalid_argument("ParallelForces: needs threads >= 1 and chunks >= threads");
  stats_.resize(chunks_);
  follow_model();
  for (int t = 1; t < threads; ++t) helpers_.emplace_back([this] { helper(); });
}

void ParallelForces::follow_model() {
  const std::size_t nodes = model_.node_count();
  buffers_.assign(chunks_ - 1, std::vector<Vec3>(nodes, Vec3::Zero()));
  ranges_.assign(chunks_, {0, 0});
  const auto& mesh = model_.rest_mesh();
  for (std::size_t c = 1; c < chunks_; ++c) {
    const auto [first, last] = model_.part_elements(ElementPart{c, chunks_});
    const auto [lo, hi] = tissue::node_range(mesh, first, last);
    ranges_[c] = {static_cast<std::size_t>(lo), static_cast<std::size_t>(hi)};
  }
}

ParallelForces::~ParallelForces() {
  stop_.store(true);
  go_.fetch_add(1, std::memory_order_release);
  go_.notify_all();
  for (auto& h : helpers_) h.join();
}

void ParallelForces::take_chunks(std::uint64_t generation) {
  std::uint64_t v = next_.load(std::memory_order_acquire);
  for (;;) {
    if ((v >> 32) != generation || (v & 0xffffffffu) >= chunks_) return;
    if (!next_.compare_exchange_weak(v, v + 1, std::memory_order_acq_rel)) continue;
    (*job_)(v & 0xffffffffu);
    finished_.fetch_add(1, std::memory_order_acq_rel);
    finished_.notify_one();
    v = next_.load(std::memory_order_acquire);
  }
}

void ParallelForces::run(const std::function<void(std::size_t chunk)>& job) {
  job_ = &job;
  finished_.store(0, std::memory_order_relaxed);
  const std::uint64_t g = ++generation_;
  next_.store(g << 32 | 1u, std::memory_order_release);
  go_.store(g, std::memory_order_release);
  go_.notify_all();
  job(0);
  take_chunks(g);
  // The remaining chunks are being computed by helpers: wait for them, spinning for up to 0.3 ms,
  // then asleep. A caller that only spins keeps its core busy, so a lowest-priority helper that
  // another thread holds off its own core is not moved over (96k tets with the haptic client on
  // the other core: ticks of up to 90-200 ms in 2 runs against 35-56 ms with the sleep).
  const auto spin_until = std::chrono::steady_clock::now() + std::chrono::microseconds(300);
  for (std::size_t done = finished_.load(std::memory_order_acquire); done < chunks_ - 1; done = finished_.load(std::memory_order_acquire)) {
    if (std::chrono::steady_clock::now() < spin_until) continue;
    finished_.wait(done, std::memory_order_acquire);
  }
}

void ParallelForces::helper() {
  // SCHED_IDLE: the helper runs only on a core nothing else wants, and the kernel counts a core
  // that runs nothing but such threads as idle when it places a waking thread, so the command
  // thread and the clients' threads go straight there. With nice 19 instead, the busy helper's
  // core was not idle and they could queue behind the physics thread (the runs are in
  // docs/SCENE.md, "Physics threads"). The physics thread takes the
  // helper's chunks itself when the helper is held off. Nice 19 where SCHED_IDLE is refused.
  // A server started with real-time priority (a station's unit, docs/DEPLOY.md) keeps it for the
  // helper: a SCHED_IDLE helper that has taken a chunk is held off by any other process on its
  // core (a browser drawing the console), and the real-time physics thread waits for that chunk
  // (bench/station.sh on the 12k liver, three interleaved pairs of 30 s: 33-40% of the slots
  // missed with SCHED_IDLE, 17-27% with this). Two levels below the process, so that a haptic
  // client deployed one below the server (49 under 50) still preempts it.
  const int process_policy = sched_getscheduler(getpid());
  if (sched_param p{}; (process_policy == SCHED_FIFO || process_policy == SCHED_RR) && sched_getparam(getpid(), &p) == 0) {
    p.sched_priority = std::max(sched_get_priority_min(process_policy), p.sched_priority - 2);
    pthread_setschedparam(pthread_self(), process_policy, &p);
  } else {
    const sched_param idle{};
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0) setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);
  }
  pthread_setname_np(pthread_self(), "forces-helper");
  std::uint64_t seen = 0;
  for (;;) {
    go_.wait(seen, std::memory_order_acquire);
    seen = go_.load(std::memory_order_acquire);
    if (stop_.load()) return;
    take_chunks(seen);
  }
}

ForceStats ParallelForces::evaluate(std::span<const Vec3> x, std::span<Vec3> f, const tissue::MemoryUpdate& memory) {
  // The model's mesh is not read here: a material being built on another thread may share it. A
  // cut is reported (follow_model); forces for more nodes than the buffers hold follow it too.
  if (!buffers_.empty() && buffers_[0].size() != f.size()) follow_model();
  unsummed_ = {};
  const auto job = [&](std::size_t c) {
    if (c == 0) {
      stats_[0] = model_.add_forces(x, f, memory, ElementPart{0, chunks_});
      return;
    }
    auto& buffer = buffers_[c - 1];
    std::fill(buffer.begin() + static_cast<long>(ranges_[c].first), buffer.begin() + static_cast<long>(ranges_[c].second), Vec3::Zero());
    stats_[c] = model_.add_forces(x, buffer, memory, ElementPart{c, chunks_});
  };
  run(std::cref(job));  // by reference: a std::function holding the closure itself would allocate every sub-step
  double worst = stats_[0].max_edge_strain;
  for (std::size_t c = 1; c < chunks_; ++c) {
    const double s = stats_[c].max_edge_strain;
    worst = std::isnan(s) || std::isnan(worst) ? std::numeric_limits<double>::quiet_NaN() : std::max(worst, s);
  }
  return {worst};
}

void ParallelForces::add_buffers(std::span<Vec3> f, std::size_t first, std::size_t last) const {
  for (std::size_t c = 1; c < chunks_; ++c) {
    const Vec3* b = buffers_[c - 1].data();
    for (std::size_t i = std::max(first, ranges_[c].first), end = std::min(last, ranges_[c].second); i < end; ++i) f[i] += b[i];
  }
}

ForceStats ParallelForces::operator()(std::span<const Vec3> x, std::span<Vec3> f, const tissue::MemoryUpdate& memory) {
  const ForceStats stats = evaluate(x, f, memory);
  add_buffers(f, 0, f.size());
  return stats;
}

ForceStats ParallelForces::evaluate_leaving_sums(std::span<const Vec3> x, std::span<Vec3> f, const tissue::MemoryUpdate& memory) {
  const ForceStats stats = evaluate(x, f, memory);
  unsummed_ = f;
  return stats;
}

void ParallelForces::for_ranges(std::size_t n, const std::function<void(std::size_t first, std::size_t last)>& body) {
  const std::span<Vec3> f = unsummed_;
  unsummed_ = {};
  if (!f.empty() && f.size() != n) throw std::logic_error("ParallelForces::for_ranges: the node count is not that of the forces left to sum");
  const auto sum_then_body = [&](std::size_t first, std::size_t last) {
    if (!f.empty()) add_buffers(f, first, last);
    body(first, last);
  };
  if (helpers_.empty() || n < kParallelNodesFrom) {
    sum_then_body(0, n);
    return;
  }
  const auto job = [&](std::size_t c) { sum_then_body(n * c / chunks_, n * (c + 1) / chunks_); };
  run(std::cref(job));
}

}  // namespace viscera::runtime
