#include "viscera/runtime/mesh_publisher.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <pthread.h>

namespace viscera::runtime {

namespace proto = viscera::protocol;

void copy_surface(std::span<const tissue::Vec3> x, std::span<const std::int32_t> nodes, float* out) {
  for (const auto n : nodes)
    for (int d = 0; d < 3; ++d) *out++ = static_cast<float>(x[n][d]);
}

MeshPublisher::MeshPublisher(std::unique_ptr<MeshStream> stream, const proto::SurfaceTopology& topology, std::vector<std::int32_t> surface_nodes,
                             double rate_hz)
    : stream_(std::move(stream)), nodes_(std::move(surface_nodes)), mesh_id_(topology.mesh_id), period_ns_(static_cast<std::int64_t>(1e9 / rate_hz)) {
  readers_ever_ = stream_->topology_readers_ever();
  stream_->write_topology(mesh_id_, proto::encode(topology));
  sent_ = {topology.mesh_id, topology.topology_generation, nodes_, topology.triangles};
  whole_ = topology;
  pending_.mesh_id = mesh_id_;
  pending_.positions.resize(3 * nodes_.size());
  thread_ = std::thread([this] {
    pthread_setname_np(pthread_self(), "mesh-publisher");
    publish_loop();
  });
}

MeshPublisher::~MeshPublisher() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  ready_cv_.notify_one();
  thread_.join();
}

void MeshPublisher::offer(std::span<const tissue::Vec3> x, double sim_time_s, std::int64_t now_ns, std::uint64_t tick) {
  if (now_ns < next_due_ns_) return;
  next_due_ns_ = std::max(next_due_ns_ + period_ns_, now_ns);  // steady cadence, no burst after a stall
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) {  // the publisher is swapping buffers this very moment
    ++skipped_;
    return;
  }
  if (ready_) ++skipped_;  // the previous snapshot was never taken: the newer one replaces it
  pending_.positions.resize(3 * nodes_.size());
  copy_surface(x, nodes_, pending_.positions.data());
  pending_.topology_generation = topology_generation_;
  pending_.frame = ++offered_;
  pending_.tick = tick;
  pending_.sim_time_s = sim_time_s;
  pending_.server_stamp_ns = now_ns;
  ready_ = true;
  lock.unlock();
  ready_cv_.notify_one();
}

void MeshPublisher::change_topology(proto::SurfaceTopology topology, std::vector<std::int32_t> surface_nodes) {
  std::lock_guard lock(mutex_);  // the publisher holds it only to swap buffers
  topology_generation_ = topology.topology_generation;
  nodes_ = std::move(surface_nodes);
  pending_topology_ = std::move(topology);
  pending_topology_nodes_ = nodes_;
  ready_ = false;  // a frame of the old surface not yet taken is dropped: it must not follow the new topology
}

std::uint64_t MeshPublisher::topologies_published() const {
  std::lock_guard lock(mutex_);
  return topologies_;
}

std::uint64_t MeshPublisher::patches_published() const {
  std::lock_guard lock(mutex_);
  return patches_;
}

std::uint64_t MeshPublisher::topology_change_bytes() const {
  std::lock_guard lock(mutex_);
  return change_bytes_;
}

std::uint64_t MeshPublisher::frames_published() const {
  std::lock_guard lock(mutex_);
  return published_;
}

void MeshPublisher::publish_loop() {
  proto::MeshFrame frame;  // the buffer being written; swapped with pending_, so set up alike
  frame.mesh_id = mesh_id_;
  frame.positions.resize(pending_.positions.size());
  for (;;) {
    std::optional<proto::SurfaceTopology> topology;
    std::vector<std::int32_t> topology_nodes;
    {
      std::unique_lock lock(mutex_);
      ready_cv_.wait(lock, [this] { return ready_ || stop_; });
      if (stop_) return;
      std::swap(frame, pending_);  // O(1): the physics thread fills the other buffer next time
      ready_ = false;
      topology.swap(pending_topology_);
      topology_nodes.swap(pending_topology_nodes_);
    }
    try {
      // A reader joined: its history (the last 16 messages) may hold only patches, so the whole
      // surface goes out now (the new one, if it changed, else the one the others hold).
      const std::uint64_t readers = stream_->topology_readers_ever();
      const bool joined = readers > readers_ever_;
      if (joined && !topology) {
        stream_->write_topology(mesh_id_, proto::encode(whole_));
        readers_ever_ = readers;
        patches_since_whole_ = 0;
        std::lock_guard lock(mutex_);
        ++topologies_;
      }
      if (topology) {
        // A patch of what the readers hold where it is smaller; whole when a reader joined, and
        // after kPatchesPerWhole patches.
        std::optional<proto::SurfaceTopology> patch;
        if (!joined && patches_since_whole_ < kPatchesPerWhole) patch = surface_patch(sent_, *topology, topology_nodes);
        const proto::SurfaceTopology& message = patch ? *patch : *topology;
        // Reliable: a topology that cannot be written is written again before the next frame.
        try {
          stream_->write_topology(mesh_id_, proto::encode(message));
        } catch (const proto::DdsError&) {
          std::lock_guard lock(mutex_);
          if (!pending_topology_) {
            pending_topology_ = std::move(topology);
            pending_topology_nodes_ = std::move(topology_nodes);
          }
          continue;
        }
        patches_since_whole_ = patch ? patches_since_whole_ + 1 : 0;
        if (joined) readers_ever_ = readers;
        std::lock_guard lock(mutex_);
        ++topologies_;
        patches_ += patch ? 1 : 0;
        change_bytes_ += surface_array_bytes(message);
        sent_ = {topology->mesh_id, topology->topology_generation, std::move(topology_nodes), topology->triangles};
        whole_ = std::move(*topology);
      }
      stream_->write_frame(mesh_id_, proto::encode(frame));
    } catch (const proto::DdsError&) {
      continue;  // a frame lost to the transport; the next one follows in 1/rate s
    }
    std::lock_guard lock(mutex_);
    ++published_;
  }
}

}  // namespace viscera::runtime
