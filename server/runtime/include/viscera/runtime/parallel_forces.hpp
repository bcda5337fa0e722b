#pragma once  // SPDX-License-Identifier: Apache-2.0
// Internal forces of a tissue model on several threads. The elements are cut into a fixed number
// of chunks; the calling thread computes chunk 0 straight into the force array, and it and the
// helper threads take the other chunks as they come, each into the chunk's own buffer. The
// buffers are added after in chunk order, so the forces are the same bit for bit whichever thread
// computed which chunk, and for any number of threads with the same chunks (deterministic; they
// differ from ForceModel::add_forces in one piece only by rounding). One thread takes every chunk
// itself: the server evaluates in kForceChunks chunks on one thread and on two, so that a session
// re-simulated on the other number gives the same bits (docs/RECORDING.md); more threads than
// that take a chunk each. Every chunk beyond the first costs its buffer, cleared and added over
// the nodes its elements name only: in locality order (mesh/locality_order.hpp, as the server
// orders an organ) the last chunk's range is exactly its own nodes. More chunks than threads did
// not pay on the 12k liver, even so (docs/PERFORMANCE-LOG.md).
// A helper that is late (the machine's other core busy) costs nothing but the buffers: the
// calling thread then takes its chunks. Helpers sleep between evaluations (no spinning); the
// caller, waiting for a helper's chunk, spins briefly and then sleeps.
// The same threads split the integrator's node update (for_ranges) on a large organ. The server
// leaves the buffers' sum to that loop (evaluate_leaving_sums): each range adds them over its own
// nodes before it moves them, so the sum is split with the nodes instead of taking one thread a
// pass per buffer; per node it adds the chunks in the same order, whatever the split.
#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <thread>
#include <utility>
#include <vector>

#include "viscera/tissue/model/force_model.hpp"

namespace viscera::runtime {

/// The chunks the server cuts the elements into on one or two threads (more threads: one each).
inline constexpr int kForceChunks = 2;
/// Node loops (ParallelForces::for_ranges) shorter than this run on the calling thread alone. The
/// integrator's node update on two threads (bench/tick_bench NodesOnly, Intel VM, 2026-11-28): on
/// the 96k liver (19,535 nodes) 2.1 ns a node less, on the 12k liver (2,936 nodes) 13 us a sub-step
/// more, the helper's wake-up; so a split pays from about 6,200 nodes.
inline constexpr std::size_t kParallelNodesFrom = 8192;

class ParallelForces {
 public:
  /// `threads` >= 1 (the calling thread and threads - 1 helpers); `chunks` >= threads.
  ParallelForces(const tissue::ForceModel& model, int threads, int chunks = 4);
  ~ParallelForces();
  ParallelForces(const ParallelForces&) = delete;
  ParallelForces& operator=(const ParallelForces&) = delete;

  /// f += the model's internal forces at x, memory advanced (as ForceModel::add_forces).
  tissue::ForceStats operator()(std::span<const tissue::Vec3> x, std::span<tissue::Vec3> f, const tissue::MemoryUpdate& memory);
  /// The same, but the chunks' buffers are not yet added to f: the next for_ranges adds them,
  /// range by range, before its body. Until then f holds only chunk 0's forces (and what the
  /// caller adds).
  tissue::ForceStats evaluate_leaving_sums(std::span<const tissue::Vec3> x, std::span<tissue::Vec3> f, const tissue::MemoryUpdate& memory);
  /// body(first, last) over ranges that split [0, n) into one per chunk, on the calling thread and
  /// the helpers; returns when all are done. Fewer than kParallelNodesFrom, or no helper: one call.
  /// After evaluate_leaving_sums (n then the size of its f), each range first adds the buffers.
  void for_ranges(std::size_t n, const std::function<void(std::size_t first, std::size_t last)>& body);
  /// After the model's mesh changed (a cut): the nodes each chunk writes to, found again.
  void follow_model();

 private:
  void helper();
  /// Takes chunks of evaluation `generation` until none is left.
  void take_chunks(std::uint64_t generation);
  /// job(0) on the calling thread; job(1 .. chunks-1) on whichever thread takes it first (the
  /// caller too, once its own is done). Returns when every chunk is done.
  void run(const std::function<void(std::size_t chunk)>& job);
  /// The chunks computed, chunk 0 into f, the others into their buffers; the stats combined.
  tissue::ForceStats evaluate(std::span<const tissue::Vec3> x, std::span<tissue::Vec3> f, const tissue::MemoryUpdate& memory);
  /// f[i] += every buffer's force at i, for i in [first, last), in chunk order.
  void add_buffers(std::span<tissue::Vec3> f, std::size_t first, std::size_t last) const;

  const tissue::ForceModel& model_;
  const std::size_t chunks_;
  // The work in progress: written by the calling thread before it publishes the generation.
  const std::function<void(std::size_t chunk)>* job_ = nullptr;
  std::vector<std::vector<tissue::Vec3>> buffers_;  // chunks 1 .. chunks-1, a force per node of the model
  // The nodes chunk c writes to, [first, second): only those of its buffer are cleared and added.
  std::vector<std::pair<std::size_t, std::size_t>> ranges_;
  std::vector<tissue::ForceStats> stats_;
  std::span<tissue::Vec3> unsummed_;  // the f of evaluate_leaving_sums, until for_ranges adds its buffers
  // next_: generation in the high 32 bits, next chunk in the low 32; taken by compare-exchange so
  // a helper still in an old evaluation never takes a chunk of a new one.
  std::atomic<std::uint64_t> next_{0};
  std::atomic<std::uint64_t> go_{0};  // generation to work on; helpers wait on it
  std::atomic<std::size_t> finished_{0};  // chunks 1.. finished in this generation
  std::atomic<bool> stop_{false};
  std::uint64_t generation_ = 0;
  std::vector<std::thread> helpers_;
};

}  // namespace viscera::runtime
