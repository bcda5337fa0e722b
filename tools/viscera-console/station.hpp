#pragma once  // SPDX-License-Identifier: Apache-2.0
// One trainee station: a server on the domain in a DDS partition of its own. Its streams are
// taken on a thread of the station's (client SDK's StreamTap), decoded, thinned to what a page
// needs and handed to the bridge as ready-to-send messages; requests from browsers are carried out
// on a second thread through the SDK's Client, whose calls wait for the server's answer. An
// instrument the console has taken over is commanded by a third thread at 200 Hz, from the tip
// the instructor moves it to (so its lease never runs out while the instructor thinks).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "viscera/client/client.hpp"
#include "viscera/console/browser_request.hpp"
#include "viscera/console/outbox.hpp"
#include "viscera/protocol/dds.hpp"

namespace viscera::console {

/// Where a station's messages go (called on the station's thread; must not block).
struct StationSink {
  std::function<void(std::shared_ptr<const std::string> frame)> frame;
  std::function<void(OutMessage m)> message;
  /// Every payload as it came off the domain, for Foxglove clients; called only while `wants_raw`.
  std::function<void(protocol::Stream stream, std::int64_t stamp_ns, std::shared_ptr<const std::vector<std::uint8_t>> payload)> raw;
  std::function<bool()> wants_raw;
};

/// What a browser that starts watching gets at once.
struct StationSnapshot {
  std::shared_ptr<const std::string> topology, frame, scene, telemetry;
};

class Station {
 public:
  /// `partition`: the DDS partition ("" : the default). `client_id`: the console's id on the
  /// domain (its annotations and requests carry it).
  Station(std::uint32_t domain, std::string partition, std::uint32_t client_id, double force_period_s, StationSink sink);
  ~Station();
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  const std::string& name() const { return name_; }
  StationSnapshot snapshot() const;
  /// Queues a request; `reply` gets {"type": "reply", "id", "ok", "message"} from the request
  /// thread. False (nothing queued) when 32 are already waiting.
  bool request(const BrowserRequest& r, std::function<void(nlohmann::json)> reply);
  /// Moves an instrument the console holds (taken over) by `delta` [m], kept within the organ's
  /// bounds widened by 5 cm; false and why if the console does not hold it.
  bool move(std::uint32_t instrument, const protocol::Vector3& delta, std::string* why);
  /// Payloads that failed verification and were dropped.
  std::uint64_t rejected() const { return rejected_; }
  /// The delay from the server's surface frames to the bridge [ms]: p50 and p99 of the last 1000
  /// (the DDS leg of the page's delay; the same clock on one host, synchronised clocks across).
  std::pair<double, double> frame_delay_ms() const;

 private:
  void stream_loop();
  void request_loop();
  void drive_loop();
  /// The message as the page gets it: with the station's name, encoded once for every browser.
  std::shared_ptr<const std::string> tagged(nlohmann::json j) const;

  std::uint32_t domain_;
  std::string partition_, name_;
  std::uint32_t client_id_;
  double force_period_s_;
  StationSink sink_;
  mutable std::mutex mutex_;
  StationSnapshot snapshot_;
  std::map<std::uint32_t, protocol::Vector3> tips_;  ///< each instrument's newest commanded tip [m]
  protocol::Vector3 bounds_min_{}, bounds_max_{};  ///< the organ's, from the scene state [m]
  std::map<std::uint32_t, protocol::Vector3> held_;  ///< instruments the console drives, at these tips
  std::deque<double> frame_delays_ms_;  ///< the last 1000 surface frames' delays to the bridge [ms]
  std::deque<std::pair<BrowserRequest, std::function<void(nlohmann::json)>>> requests_;
  std::condition_variable requests_cv_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> rejected_{0};
  std::unique_ptr<client::Client> client_;  // the worker's requests and the driver's commands (thread-safe for that)
  std::thread streams_, worker_, driver_;
};

}  // namespace viscera::console
