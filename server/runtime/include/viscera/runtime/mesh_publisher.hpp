#pragma once  // SPDX-License-Identifier: Apache-2.0
// Publishes the organ's deformed surface at 30-60 Hz from a thread of its own, so that encoding
// and writing 100 kB-1 MB frames never delays the physics loop (docs/PROTOCOL.md: never write from
// the physics thread). The physics thread only offers its state: when a frame is due, it copies
// the surface positions into a hand-over buffer, and if the publisher is still busy with that
// buffer it skips the frame instead of waiting. The topology is published reliably and transient
// local, so clients that join later still get it; after a cut as a patch of the one before
// (surface_message.hpp). The whole surface goes out again when a reader joins (the stream's last 16
// messages may all be patches), and after kPatchesPerWhole patches for a reader that lost some.
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/server_endpoints.hpp"
#include "viscera/runtime/surface_message.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::runtime {

/// The surface vertices' positions as frames carry them: x, y, z of node `nodes[k]` at out[3k..3k+2].
void copy_surface(std::span<const tissue::Vec3> x, std::span<const std::int32_t> nodes, float* out);

class MeshPublisher {
 public:
  /// `surface_nodes[k]` is the mesh node of surface vertex k; `triangles` index surface vertices.
  MeshPublisher(std::unique_ptr<MeshStream> stream, const protocol::SurfaceTopology& topology, std::vector<std::int32_t> surface_nodes,
                double rate_hz);
  ~MeshPublisher();
  MeshPublisher(const MeshPublisher&) = delete;
  MeshPublisher& operator=(const MeshPublisher&) = delete;

  /// Physics thread: hands over the state after `tick` if a frame is due at `now_ns`; never blocks.
  void offer(std::span<const tissue::Vec3> x, double sim_time_s, std::int64_t now_ns, std::uint64_t tick);
  /// Physics thread: whether offer() at `now_ns` would take a frame.
  bool due(std::int64_t now_ns) const { return now_ns >= next_due_ns_; }
  /// Physics thread: the organ's surface changed (a cut). Frames offered from now on are of
  /// `topology` (its topology_generation), which is written before the first of them; a change
  /// not yet written is replaced by a newer one. Encoding and writing happen on the publisher's
  /// thread.
  void change_topology(protocol::SurfaceTopology topology, std::vector<std::int32_t> surface_nodes);
  std::uint64_t topologies_published() const;
  /// Of them, the patches, and the bytes of the arrays written for topologies after the first.
  std::uint64_t patches_published() const;
  std::uint64_t topology_change_bytes() const;
  /// A whole surface after at most this many patches, for a reader that fell more than the
  /// stream's 16 messages behind and lost patches (a reader that joins gets one at once).
  static constexpr int kPatchesPerWhole = 64;
  std::uint64_t frames_published() const;
  /// Frames that were due while the publisher was still writing the previous one.
  std::uint64_t frames_skipped() const { return skipped_; }

 private:
  void publish_loop();

  std::unique_ptr<MeshStream> stream_;
  std::vector<std::int32_t> nodes_;
  std::uint32_t mesh_id_;
  std::uint32_t topology_generation_ = 0;  // physics thread: of the frames offered
  std::int64_t period_ns_, next_due_ns_ = 0;
  std::uint64_t offered_ = 0, skipped_ = 0;  // physics thread only

  mutable std::mutex mutex_;
  std::condition_variable ready_cv_;
  protocol::MeshFrame pending_;  // guarded by mutex_
  std::optional<protocol::SurfaceTopology> pending_topology_;  // guarded by mutex_: to write before pending_
  std::vector<std::int32_t> pending_topology_nodes_;  // guarded by mutex_: its vertices' mesh nodes
  bool ready_ = false, stop_ = false;
  std::uint64_t published_ = 0, topologies_ = 1, patches_ = 0, change_bytes_ = 0;  // guarded by mutex_
  SentSurface sent_;  // publisher thread: what the stream's readers hold
  protocol::SurfaceTopology whole_;  // publisher thread: the whole surface they hold
  std::uint64_t readers_ever_ = 0;  // publisher thread: topology readers matched, when the last whole surface went out
  int patches_since_whole_ = 0;  // publisher thread
  std::thread thread_;
};

}  // namespace viscera::runtime
