#pragma once  // SPDX-License-Identifier: Apache-2.0
// What the console's web server shares between its files (not a public header): the server's
// state (one io thread), the connection that reads HTTP requests, and the start of a browser's
// WebSocket session, over plain TCP (loopback) or TLS.
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>

#include "station.hpp"
#include "web_server.hpp"

namespace viscera::console {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

/// A browser's connection: plain TCP (a console on loopback) or TLS (HTTPS and WSS).
using PlainStream = beast::tcp_stream;
using TlsStream = beast::ssl_stream<beast::tcp_stream>;
using Transport = std::variant<PlainStream, TlsStream>;

double seconds_since(std::chrono::steady_clock::time_point t);
/// The value of `key` in a query string or a cookie header ("a=1&b=2", "a=1; b=2").
std::string field_value(std::string_view list, std::string_view key, char separator);

class Browser;

struct Counters {
  std::uint64_t http_requests = 0, refused = 0, not_found = 0, browsers_opened = 0, malformed = 0, rate_limited = 0, oversized = 0, closed_slow = 0,
                closed_flood = 0, busy = 0, tls_failed = 0, plain_refused = 0;
};

struct WebServer::Impl : std::enable_shared_from_this<WebServer::Impl> {
  asio::io_context& io;
  tcp::acceptor acceptor;
  WebOptions opt;
  std::vector<Station*> stations;
  Counters counters;
  std::map<std::uint64_t, std::shared_ptr<Browser>> browsers;
  std::uint64_t next_id = 1;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  bool stopped = false;
  std::atomic<int> foxglove_browsers{0};
  /// Per station, the newest payload of each stream whose newest sample is its state (scene,
  /// surface topology, scene files): a Foxglove client that subscribes gets it at once.
  std::vector<std::map<protocol::Stream, std::pair<std::int64_t, std::shared_ptr<const std::vector<std::uint8_t>>>>> latched;

  Impl(asio::io_context& io_, const tcp::endpoint& ep, WebOptions o, std::vector<Station*> s)
      : io(io_), acceptor(io_, ep), opt(std::move(o)), stations(std::move(s)), latched(stations.size()) {}
  void accept();
  bool authorised(const http::request<http::string_body>& req, bool* from_query) const;
  nlohmann::json stats() const;
  void add_station(Station* s);
};

/// Reads HTTP requests on a new connection, after the TLS handshake where the console has TLS (http_connection.cpp).
void serve_http(tcp::socket socket, std::shared_ptr<WebServer::Impl> server);
/// Upgrades to a browser's WebSocket session (web_server.cpp): `station` watched, Foxglove or the page's protocol.
void open_browser(Transport&& stream, std::shared_ptr<WebServer::Impl> server, http::request<http::string_body>&& upgrade, std::size_t station,
                  bool foxglove);

}  // namespace viscera::console
