#pragma once  // SPDX-License-Identifier: Apache-2.0
// The bridge's side toward browsers: an HTTP server (Boost.Beast, over TLS where given a
// certificate) that serves the page's files and a WebSocket at /ws. Access needs the token (in the address, ?token=..., or the cookie the
// page is given), checked before anything is served or upgraded. Each browser has a bounded
// outbox (outbox.hpp), a rate limit on its requests and a size limit on its messages; everything
// runs on one thread (the io_context's), stations hand their messages over by posting to it.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <nlohmann/json.hpp>

#include "viscera/console/outbox.hpp"
#include "viscera/protocol/dds.hpp"

namespace viscera::console {

class Station;

struct WebOptions {  // NOLINT(bugprone-exception-escape): its defaults do not throw
  std::string token;
  std::shared_ptr<boost::asio::ssl::context> tls;  ///< HTTPS and WSS with it (make_tls_context); null: plain HTTP
  std::map<std::string, std::string> files;  ///< path ("/console.js") -> content
  std::size_t outbox_bytes = 4u << 20;  ///< per browser
  double requests_per_s = 20, request_burst = 40;
  std::uint32_t max_browsers = 32;
  nlohmann::json page_settings;  ///< sent to each browser in its hello (force limit, ...)
  std::string recordings_dir;  ///< the recordings a browser may open for replay ("" : none)
  std::vector<std::string> allowed_origins;  ///< WebSocket origins besides the console's own (origin_allowed)
  /// Starts a replay of `file` (in recordings_dir) as a new station: its Station, or nullptr and why.
  std::function<Station*(const std::string& file, std::string* why)> open_replay;
};

class WebServer {
 public:
  WebServer(boost::asio::io_context& io, const boost::asio::ip::tcp::endpoint& listen, WebOptions options, std::vector<Station*> stations);
  ~WebServer();
  /// The address it listens on (the port chosen when 0 was asked for).
  boost::asio::ip::tcp::endpoint endpoint() const;
  /// Thread-safe: hand a station's newest frame / a message to every browser watching it.
  void post_frame(std::size_t station, std::shared_ptr<const std::string> frame);
  void post_message(std::size_t station, OutMessage m);
  /// Thread-safe: a payload as it came off the domain, for the Foxglove clients subscribed to its
  /// stream; wants_raw() says whether any is connected (else the station need not copy them).
  void post_raw(std::size_t station, protocol::Stream stream, std::int64_t stamp_ns, std::shared_ptr<const std::vector<std::uint8_t>> payload);
  bool wants_raw() const;
  /// A station added at run time (a replay, a server found on the domain), as station number
  /// stations().size(): every browser gets the new list. Call on the io thread.
  void add_station(Station* station);
  /// Counters, per browser and in all (the io thread's view; call on it, or from /stats).
  nlohmann::json stats() const;

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace viscera::console
