#pragma once  // SPDX-License-Identifier: Apache-2.0
// The one wrapper of Cyclone DDS's C API in viscera: RAII entities, the envelope topic per
// stream with its QoS (docs/PROTOCOL.md), and typed writes/takes of FlatBuffer payloads. No other
// code calls dds_* directly.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace viscera::protocol {

class DdsError : public std::runtime_error {
 public:
  /// "DDS: <what>: <the code's name>[: <detail>]"
  DdsError(const std::string& what, int32_t code, const std::string& detail = {});
};

/// The streams of the protocol; each is one topic of Envelope with its own QoS.
enum class Stream {
  instrument_command,  ///< best effort, keep last 1 per key, volatile
  force_feedback,  ///< best effort, keep last 1 per key, volatile
  session_request,  ///< reliable, keep last 16, volatile
  scene_state,  ///< reliable, keep last 1, transient local (late joiners get it)
  telemetry,  ///< best effort, keep last 1, volatile
  surface_topology,  ///< reliable, keep last 1 per key, transient local (late joiners get it)
  mesh_frame,  ///< reliable, keep last 1 per key, volatile (slow readers skip frames)
  event,  ///< reliable, keep last 64, volatile (server events and client annotations)
  // schema 7:
  scene_files,  ///< reliable, keep last 1, transient local (what the scene was built from)
  lockstep_step,  ///< reliable, keep all, volatile (a lockstep driver's ticks)
  lockstep_result,  ///< reliable, keep all, volatile (what each lockstep tick produced)
};
constexpr int kStreamCount = 11;

/// The liveliness lease of every writer: a client or server silent this long is gone. The server
/// also releases the instruments of an owner silent this long.
inline constexpr std::chrono::milliseconds kLivelinessLease{500};
/// The DDS topic ("viscera_force_feedback") and the stream's own name ("force_feedback").
const char* topic_name(Stream s);
const char* stream_name(Stream s);
/// The stream with that name; false if there is none.
bool parse_stream(const std::string& name, Stream* out);

class Participant {
 public:
  /// `partition`: the DDS partition of every reader and writer made on it ("" : the default). A
  /// replay runs in a partition of its own, so it never drives a live server's instruments.
  /// `role`: carried in the user data of every writer made on it, so that discovery tells a live
  /// server (kServerRole) from a replayer that publishes the same streams.
  explicit Participant(std::uint32_t domain_id, std::string partition = {}, std::string role = {});
  const std::string& partition() const { return partition_; }
  const std::string& role() const { return role_; }
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  int32_t handle() const { return handle_; }
  /// The envelope topic of a stream (created once per participant).
  int32_t topic(Stream s);

 private:
  int32_t handle_;
  int32_t topics_[kStreamCount] = {};
  std::string partition_, role_;
};

/// The role of a viscera-server's writers (live or lockstep).
inline constexpr const char* kServerRole = "viscera-server";
/// A station (one trainee's server and its clients) is a DDS partition of that name; "" is the
/// default partition. Why `name` cannot name one, or "" if it can: a DDS wildcard ('*', '?') would
/// reach other stations' partitions, and only letters, digits, '-', '_' and '.' (at most 64) fit the
/// partition lists of DDS Security permissions and a log line (docs/DEPLOY.md).
std::string station_name_problem(const std::string& name);
/// A program's --station value: `name`, or common::UsageError("<flag>: <the problem>").
std::string checked_station(const std::string& name, const std::string& flag = "--station");

struct Received {
  std::uint32_t source_id;
  std::uint64_t seq;
  std::int64_t stamp_ns;
  std::span<const std::uint8_t> payload;  ///< valid during the callback only
  std::uint64_t writer = 0;  ///< the writing DDS entity (its instance handle), for counting its sequence gaps
  /// The writer's DDS participant (a hash of its GUID; 0: not known): who sent it.
  std::uint64_t participant = 0;
  /// The first 48 bits of that participant's GUID (0: not known). Under DDS Security they are
  /// derived from the subject name of its certificate and checked in the authentication handshake
  /// (DDS Security 1.1, 9.3.3), so every participant of one certificate has the same identity and
  /// no other can take it; without security they are random for each process.
  std::uint64_t identity = 0;
};

/// Whether the Cyclone configuration of this process (CYCLONEDDS_URI: its files and inline XML)
/// configures DDS Security, so that Received::identity names a certificate.
bool security_configured();

/// A reader's history, for a reader that must keep every sample (a recorder) rather than the
/// stream's own (keep last 1 for the 1 kHz streams).
struct ReaderOptions {
  int history_depth = 0;  ///< > 0: keep the last N per key; 0: the stream's history
};

class Writer {
 public:
  Writer(Participant& p, Stream s);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  void write(std::uint32_t source_id, std::span<const std::uint8_t> payload);
  /// Number of matched readers.
  int matched() const;
  /// Readers matched since the writer was made, those gone included: it grows when one joins.
  std::uint64_t matched_ever() const;
  /// Waits until at least one reader is matched (a new writer's first samples reach only the
  /// readers discovered by then); false on timeout.
  bool wait_for_readers(std::chrono::milliseconds timeout) const;
  /// Waits for a first reader, then until no reader has matched for `quiet` (or `timeout` in all
  /// passed): the other readers of the domain (a recorder beside the server) learn of a new writer
  /// within milliseconds of the first, and a best-effort sample written before they do is lost to
  /// them. False if no reader matched at all.
  bool wait_for_settled_readers(std::chrono::milliseconds quiet, std::chrono::milliseconds timeout) const;
  /// Waits until every matched reliable reader acknowledged what was written; false on timeout.
  bool wait_for_acks(std::chrono::milliseconds timeout) const;

 private:
  int32_t handle_;
  std::atomic<std::uint64_t> seq_{0};  // a writer may be shared by threads (dds_write is thread-safe)
};

class Reader {
 public:
  Reader(Participant& p, Stream s, ReaderOptions options = {});
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;
  /// Takes every available sample, calling f for each; returns how many.
  int take(const std::function<void(const Received&)>& f);
  /// Blocks until data are available or the timeout passes; true if data.
  bool wait(std::chrono::nanoseconds timeout);
  /// Matched writers whose liveliness holds now: a writer whose process died counts until its
  /// lease (500 ms) runs out; one that was deleted (its process stopped cleanly) leaves at once.
  int alive_writers() const;
  /// Calls `f(alive writers)` on a DDS thread whenever the liveliness of the matched writers
  /// changes (one joins, one is deleted, or one's lease runs out). Set once, before use.
  void on_alive_writers_changed(std::function<void(int)> f);

 private:
  struct Sender {
    std::uint64_t participant, identity;
  };
  /// The participant of a writer (Received::participant, ::identity), looked up once per writer.
  Sender sender_of(std::uint64_t writer);
  int32_t handle_;
  int32_t waitset_;
  int32_t condition_;
  std::function<void(int)> on_alive_;
  std::unordered_map<std::uint64_t, Sender> senders_;  // writer -> its participant; take()'s thread
};

/// The partitions in which writers of a stream have appeared on the domain (DDS discovery: the
/// built-in publication topic), e.g. every partition that holds a viscera server (its scene state).
/// With a `role`, only writers made by participants of that role count.
class PartitionDiscovery {
 public:
  PartitionDiscovery(Participant& p, Stream s, std::string role = {});
  ~PartitionDiscovery();
  PartitionDiscovery(const PartitionDiscovery&) = delete;
  PartitionDiscovery& operator=(const PartitionDiscovery&) = delete;
  /// The partitions seen for the first time since the last call, in the order seen ("" is the
  /// default partition).
  std::vector<std::string> take_new();

 private:
  int32_t reader_;
  std::string topic_, role_;
  std::set<std::string> seen_;
};

/// The stamps of the protocol: wall-clock time in nanoseconds since the Unix epoch (dds_time).
std::int64_t now_ns();

}  // namespace viscera::protocol
