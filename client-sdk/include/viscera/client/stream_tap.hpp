#pragma once  // SPDX-License-Identifier: Apache-2.0
// Every sample of chosen streams as it came off the wire, for recorders: payloads undecoded, each
// writer's sequence numbers kept (to count what was lost), and a deep history, so that a 1 kHz
// stream read a few milliseconds late loses nothing. And its counterpart for players: payloads
// published again on their streams as they were recorded. Each on one DDS participant in one
// partition.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "viscera/protocol/dds.hpp"

namespace viscera::client {

/// The streams a session recording keeps: every stream of a session (the lockstep streams are
/// between a re-simulation's driver and its server).
std::vector<protocol::Stream> session_streams();

struct TapSample {
  protocol::Stream stream;
  std::uint32_t source_id;  ///< the envelope's key (client or instrument id)
  std::uint64_t seq;  ///< the envelope's sequence number, per writer
  std::int64_t stamp_ns;  ///< the writer's clock when written (protocol::now_ns on its host)
  std::uint64_t writer;  ///< which writer (its DDS instance handle, unique in this tap)
  std::span<const std::uint8_t> payload;  ///< valid during the callback only
};

class StreamTap {
 public:
  /// Subscribes to `streams` keeping `depth` samples per key (at most 16 of a state stream; their reliability and durability as
  /// the protocol sets them: a late joiner still gets the scene state and the surface topology).
  StreamTap(std::uint32_t domain_id, const std::string& partition, const std::vector<protocol::Stream>& streams, int depth = 4096);
  ~StreamTap();
  /// Blocks until a sample may be there or the timeout passes.
  void wait(std::chrono::milliseconds timeout);
  /// Takes every sample that arrived, in each stream's order; returns how many.
  int take(const std::function<void(const TapSample&)>& f);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Publishes recorded payloads again (a replay). It never reaches a live server: the partition must
/// be a name of its own (not the default one, no DDS wildcard), and live_server() says when a
/// viscera-server has appeared in it, whereupon the replayer stops.
class StreamPublisher {
 public:
  /// Throws std::invalid_argument for the default partition or one with a wildcard.
  StreamPublisher(std::uint32_t domain_id, const std::string& partition);
  /// Whether a viscera-server (live or lockstep) has been discovered writing in this partition.
  bool live_server();
  ~StreamPublisher();
  /// Makes the stream's writer now (so readers can discover it before the first sample).
  void open(protocol::Stream stream);
  /// Publishes a recorded payload on its stream under its recorded key (a writer per stream,
  /// made on first use).
  void publish(protocol::Stream stream, std::uint32_t source_id, std::span<const std::uint8_t> payload);
  /// Waits until every stream's writer has a matched reader or the timeout (in all) passes.
  void wait_for_readers(std::chrono::milliseconds timeout);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscera::client
