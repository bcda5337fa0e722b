#include "viscera/client/stream_tap.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <map>
#include <stdexcept>

#include "viscera/protocol/streams.hpp"

namespace viscera::client {

namespace proto = viscera::protocol;

std::vector<proto::Stream> session_streams() {
  std::vector<proto::Stream> out;
  for (const auto& s : proto::streams())
    if (s.session) out.push_back(s.stream);
  return out;
}

/// The most samples per key a state stream's reader keeps (a burst of states; a surface topology
/// is large, so not the tap's full depth).
constexpr int kStateDepth = 16;

struct StreamTap::Impl {
  proto::Participant participant;
  std::vector<std::pair<proto::Stream, std::unique_ptr<proto::Reader>>> readers;
  Impl(std::uint32_t domain, const std::string& partition) : participant(domain, partition) {}
};

StreamTap::StreamTap(std::uint32_t domain_id, const std::string& partition, const std::vector<proto::Stream>& streams, int depth)
    : impl_(std::make_unique<Impl>(domain_id, partition)) {
  for (const proto::Stream s : streams) {
    // Every sample that reaches the tap is kept until taken: `depth` per key, and for the streams
    // whose newest sample is their state (the scene, its surface, its files) up to
    // kStateDepth, so that states published milliseconds apart (a request's "preparing" and its
    // refusal) are all recorded, not the last alone (a reader of the stream's own depth, 1, lost
    // the first when both arrived between two takes).
    const bool state = proto::stream_info(s).state;
    impl_->readers.emplace_back(
        s, std::make_unique<proto::Reader>(impl_->participant, s, proto::ReaderOptions{state ? std::min(depth, kStateDepth) : depth}));
  }
}

StreamTap::~StreamTap() = default;

void StreamTap::wait(std::chrono::milliseconds timeout) {
  // Each reader has a wait set of its own: waiting on the first bounds the others' latency by the
  // timeout, which callers keep to a few milliseconds.
  if (!impl_->readers.empty()) impl_->readers.front().second->wait(timeout);
}

int StreamTap::take(const std::function<void(const TapSample&)>& f) {
  int n = 0;
  for (auto& [stream, reader] : impl_->readers)
    n += reader->take([&, s = stream](const proto::Received& r) { f({s, r.source_id, r.seq, r.stamp_ns, r.writer, r.payload}); });
  return n;
}

struct StreamPublisher::Impl {
  proto::Participant participant;
  std::map<proto::Stream, std::unique_ptr<proto::Writer>> writers;
  proto::PartitionDiscovery servers;
  bool server_seen = false;
  Impl(std::uint32_t domain, const std::string& partition)
      : participant(domain, partition), servers(participant, proto::Stream::scene_state, proto::kServerRole) {}
};

namespace {
const std::string& own_partition(const std::string& partition) {
  if (partition.empty())
    throw std::invalid_argument("a replay publishes as a station of its own, not in the default partition where live servers are");
  if (const std::string why = proto::station_name_problem(partition); !why.empty()) throw std::invalid_argument(why);
  return partition;
}
}  // namespace

StreamPublisher::StreamPublisher(std::uint32_t domain_id, const std::string& partition)
    : impl_(std::make_unique<Impl>(domain_id, own_partition(partition))) {}

bool StreamPublisher::live_server() {
  for (const auto& p : impl_->servers.take_new()) impl_->server_seen = impl_->server_seen || p == impl_->participant.partition();
  return impl_->server_seen;
}
StreamPublisher::~StreamPublisher() = default;

void StreamPublisher::open(proto::Stream stream) {
  auto& w = impl_->writers[stream];
  if (!w) w = std::make_unique<proto::Writer>(impl_->participant, stream);
}

void StreamPublisher::publish(proto::Stream stream, std::uint32_t source_id, std::span<const std::uint8_t> payload) {
  open(stream);
  impl_->writers[stream]->write(source_id, payload);
}

void StreamPublisher::wait_for_readers(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (auto& [stream, w] : impl_->writers) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
    if (left.count() <= 0) return;
    w->wait_for_readers(left);
  }
}

}  // namespace viscera::client
