#include "web_server.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <set>
#include <utility>

#include <boost/asio/post.hpp>
#include <boost/beast/websocket.hpp>

#include "viscera/common/json_input.hpp"
#include "viscera/console/access_token.hpp"
#include "viscera/console/browser_request.hpp"
#include "viscera/console/foxglove_protocol.hpp"
#include "viscera/console/rate_limit.hpp"
#include "viscera/console/recordings.hpp"
#include "viscera/protocol/streams.hpp"

#include "web_server_impl.hpp"

namespace viscera::console {

namespace websocket = beast::websocket;

double seconds_since(std::chrono::steady_clock::time_point t) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(); }

/// The value of `key` in a query string or a cookie header ("a=1&b=2", "a=1; b=2").
std::string field_value(std::string_view list, std::string_view key, char separator) {
  while (!list.empty()) {
    const auto end = list.find(separator);
    std::string_view item = list.substr(0, end);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    if (item.size() > key.size() && item.substr(0, key.size()) == key && item[key.size()] == '=') return std::string(item.substr(key.size() + 1));
    if (end == std::string_view::npos) break;
    list.remove_prefix(end + 1);
  }
  return {};
}

/// One browser's WebSocket.
class Browser : public std::enable_shared_from_this<Browser> {
 public:
  Browser(Transport&& stream, std::shared_ptr<WebServer::Impl> server, std::uint64_t id)
      : ws_(std::visit([](auto& s) { return Socket(std::in_place_type<websocket::stream<std::decay_t<decltype(s)>>>, std::move(s)); }, stream)),
        server_(std::move(server)),
        id_(id),
        outbox_(server_->opt.outbox_bytes),
        limit_(server_->opt.requests_per_s, server_->opt.request_burst) {
    beast::error_code ec;
    address_ = socket().remote_endpoint(ec).address().to_string();
    // A small kernel send buffer: what a slow browser has not taken waits in its outbox, where the
    // newest frame replaces an older one, not in a socket buffer that grows to megabytes of stale
    // frames.
    socket().set_option(asio::socket_base::send_buffer_size(128 * 1024), ec);
  }

  ~Browser() {
    if (foxglove_ && accepted_) --server_->foxglove_browsers;
  }

  /// `station`: which station it watches; `foxglove`: it speaks the Foxglove protocol.
  void start(http::request<http::string_body>&& req, std::size_t station, bool foxglove) {
    upgrade_ = std::move(req);  // kept until the handshake completes
    station_ = station;
    foxglove_ = foxglove;
    auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.idle_timeout = std::chrono::seconds(30);  // a browser that answers no ping for 30 s is gone
    std::visit(
        [&](auto& ws) {
          ws.set_option(timeouts);
          // The size of a message is this session's to count (on_read): Beast's own limit closes
          // with 1009 too, but its error is lost when the browser's side of the teardown fails,
          // and such closes went uncounted.
          ws.read_message_max(0);
          ws.set_option(websocket::stream_base::decorator([foxglove](websocket::response_type& r) {
            r.set(http::field::server, "viscera-console");
            if (foxglove) r.set(http::field::sec_websocket_protocol, kFoxgloveSubprotocol);
          }));
          ws.async_accept(upgrade_, [self = shared_from_this()](beast::error_code ec) {
            if (ec) return;
            self->server_->browsers[self->id_] = self;
            ++self->server_->counters.browsers_opened;
            self->accepted_ = true;
            if (self->foxglove_) ++self->server_->foxglove_browsers;
            self->hello();
            self->read();
          });
        },
        ws_);
  }

  std::size_t station() const { return station_; }

  void send(OutMessage m) {
    if (closing_) return;
    if (!outbox_.put(std::move(m))) {
      ++server_->counters.closed_slow;
      close_now();
      return;
    }
    pump();
  }
  void send_frame(std::shared_ptr<const std::string> f) {
    if (closing_) return;
    outbox_.put_frame(std::move(f));
    pump();
  }
  void send_json(const nlohmann::json& j) { send({std::make_shared<const std::string>(j.dump()), false, false}); }

  /// A payload for each of this Foxglove client's subscriptions to its stream.
  void send_raw(protocol::Stream stream, std::int64_t stamp_ns, const std::vector<std::uint8_t>& payload) {
    if (!foxglove_) return;
    // The 1 kHz streams may be dropped for a slow client; state and events may not.
    const bool droppable = stream == protocol::Stream::instrument_command || stream == protocol::Stream::force_feedback ||
                           stream == protocol::Stream::telemetry || stream == protocol::Stream::mesh_frame;
    for (const std::uint32_t id : subscriptions_.to(foxglove_channel(stream)))
      send({std::make_shared<const std::string>(foxglove_message_data(id, static_cast<std::uint64_t>(stamp_ns), payload)), true, droppable});
  }

  nlohmann::json stats() const {
    const double age = seconds_since(opened_);
    return {{"id", id_},
            {"address", address_},
            {"station", server_->stations[station_]->name()},
            {"connected_s", age},
            {"bytes_sent", bytes_sent_},
            {"bytes_per_s", age > 0 ? static_cast<double>(bytes_sent_) / age : 0.0},
            {"messages_sent", messages_sent_},
            {"frames_skipped", outbox_.frames_skipped()},
            {"messages_dropped", outbox_.messages_dropped()},
            {"queued_bytes", outbox_.queued_bytes()},
            {"errors_sent", errors_sent_}};
  }

  void close_now() {
    if (closing_) return;
    closing_ = true;
    beast::error_code ec;
    socket().shutdown(tcp::socket::shutdown_both, ec);
    socket().close(ec);
    leave();
  }

  bool foxglove() const { return foxglove_; }

 private:
  void hello() {
    if (foxglove_) {
      send_json(foxglove_server_info("viscera-console: " + server_->stations[station_]->name()));
      send_json(foxglove_advertise());
      return;
    }
    nlohmann::json names = nlohmann::json::array();
    for (const Station* s : server_->stations) names.push_back(s->name());
    send_json({{"type", "hello"},
               {"stations", names},
               {"recordings", list_recordings(server_->opt.recordings_dir)},
               {"settings", server_->opt.page_settings},
               {"limits", {{"requests_per_s", server_->opt.requests_per_s}, {"max_request_bytes", kMaxRequestBytes}}}});
    send_snapshot();
  }

  void send_snapshot() {
    const StationSnapshot s = server_->stations[station_]->snapshot();
    if (s.topology) send({s.topology, true, false});
    if (s.scene) send({s.scene, false, false});
    if (s.telemetry) send({s.telemetry, false, true});
    if (s.frame) send_frame(s.frame);
  }

  void error(std::uint64_t id, const std::string& message) {
    ++errors_sent_;
    send_json({{"type", "error"}, {"id", id}, {"message", message}});
  }

  /// A message is read a piece at a time: never more than kMaxRequestBytes and one piece held.
  void read() {
    std::visit(
        [this](auto& ws) {
          ws.async_read_some(in_, 16 * 1024, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
        },
        ws_);
  }

  void on_read(beast::error_code ec) {
    if (ec) {
      if (!closing_) leave();
      closing_ = true;
      return;
    }
    if (in_.size() > kMaxRequestBytes) {  // too big: closed with 1009, counted
      ++server_->counters.oversized;
      leave();
      closing_ = true;
      in_.consume(in_.size());
      std::visit([self = shared_from_this()](auto& ws) { ws.async_close(websocket::close_code::too_big, [self](beast::error_code) {}); }, ws_);
      return;
    }
    if (!std::visit([](auto& ws) { return ws.is_message_done(); }, ws_)) return read();
    const std::string message = beast::buffers_to_string(in_.data());
    in_.consume(in_.size());
    if (!limit_.allow(seconds_since(server_->start))) {
      ++server_->counters.rate_limited;
      // A browser that keeps flooding after being told is closed.
      if (++refused_in_a_row_ > 200) {
        ++server_->counters.closed_flood;
        close_now();
        return;
      }
      error(0, "rate limit: at most " + std::to_string(static_cast<int>(server_->opt.requests_per_s)) + " requests a second");
    } else if (!std::visit([](auto& ws) { return ws.got_text(); }, ws_)) {
      refused_in_a_row_ = 0;
      ++server_->counters.malformed;
      error(0, "binary messages are not requests (send JSON text)");
    } else {
      refused_in_a_row_ = 0;
      handle(message);
    }
    if (!closing_) read();
  }

  void handle(const std::string& message) {
    if (foxglove_) {
      const auto before = subscriptions_;
      if (const auto why = subscriptions_.apply(message)) {
        ++server_->counters.malformed;
        send_json(foxglove_status(2, *why));
        return;
      }
      // A new subscription to a state stream gets the state at once.
      for (const auto& [stream, latest] : server_->latched[station_])
        if (before.to(foxglove_channel(stream)).size() < subscriptions_.to(foxglove_channel(stream)).size())
          send_raw(stream, latest.first, *latest.second);
      return;
    }
    std::string why;
    const auto r = parse_browser_request(message, &why);
    if (!r) {
      ++server_->counters.malformed;
      // The reply names the request if its id can be read at all.
      const auto j = common::try_parse_json(message).value_or(nlohmann::json());
      const bool has_id = j.is_object() && j.contains("id") && j["id"].is_number_unsigned();
      error(has_id ? j["id"].get<std::uint64_t>() : 0, why);
      return;
    }
    if (r->type == RequestType::move) {
      if (!server_->stations[station_]->move(r->instrument, r->delta_m, &why)) error(r->id, why);
      return;
    }
    if (r->type == RequestType::watch) {
      for (std::size_t k = 0; k < server_->stations.size(); ++k)
        if (server_->stations[k]->name() == r->text) {
          station_ = k;
          send_json({{"type", "reply"}, {"id", r->id}, {"request", "watch"}, {"ok", true}, {"message", "watching " + r->text}, {"station", r->text}});
          send_snapshot();
          return;
        }
      error(r->id, "watch: no station '" + r->text + "'");
      return;
    }
    if (r->type == RequestType::recordings) {
      send_json({{"type", "recordings"}, {"id", r->id}, {"files", list_recordings(server_->opt.recordings_dir)}});
      return;
    }
    if (r->type == RequestType::open_recording) return open_recording(*r);
    std::weak_ptr<Browser> weak = shared_from_this();
    asio::io_context& io = server_->io;
    const auto held = std::pair{station_, r->instrument};
    const RequestType type = r->type;
    const bool queued = server_->stations[station_]->request(*r, [weak, &io, held, type, server = server_](nlohmann::json reply) {
      asio::post(io, [weak, held, type, server, reply = std::move(reply)] {
        const bool ok = reply.value("ok", false);
        auto b = weak.lock();
        // An instrument this browser took over is handed back when the browser goes, also if it
        // went before the server answered.
        if (type == RequestType::take_over && ok && (!b || b->closing_)) hand_back(*server, held);
        // Handed back by any browser of this console (they share its client id): no longer anyone's to hand back.
        if (type == RequestType::hand_back && ok)
          for (auto& [id, other] : server->browsers) other->taken_.erase(held);
        if (!b) return;
        if (type == RequestType::take_over && ok) b->taken_.insert(held);
        b->send_json(reply);
      });
    });
    if (!queued) {
      ++server_->counters.busy;
      error(r->id, "busy: 32 requests are waiting for the server");
    }
  }

  /// A recording of the folder replayed as a new station, which this browser then watches; every
  /// browser gets the new list of stations.
  void open_recording(const BrowserRequest& r) {
    if (!server_->opt.open_replay || server_->opt.recordings_dir.empty())
      return error(r.id, "open_recording: this console was started without --recordings");
    const auto files = list_recordings(server_->opt.recordings_dir);
    if (std::find(files.begin(), files.end(), r.text) == files.end()) return error(r.id, "open_recording: no recording '" + r.text + "'");
    std::string why;
    Station* s = server_->opt.open_replay(r.text, &why);
    if (!s) return error(r.id, "open_recording: " + why);
    server_->add_station(s);
    station_ = server_->stations.size() - 1;
    send_json({{"type", "reply"},
               {"id", r.id},
               {"request", "open_recording"},
               {"ok", true},
               {"station", s->name()},
               {"message", "replaying " + r.text + " as station " + s->name()}});
    send_snapshot();
  }

  /// The browser has gone: out of the list, and what it took over handed back.
  void leave() {
    server_->browsers.erase(id_);
    for (const auto& held : std::exchange(taken_, {})) hand_back(*server_, held);
  }

  static void hand_back(WebServer::Impl& server, std::pair<std::size_t, std::uint32_t> held) {
    BrowserRequest back;
    back.type = RequestType::hand_back;
    back.instrument = held.second;
    server.stations[held.first]->request(back, [](const nlohmann::json&) {});
  }

  void pump() {
    if (writing_ || closing_) return;
    auto m = outbox_.take();
    if (!m) return;
    writing_ = true;
    current_ = std::move(m->data);
    std::visit(
        [&](auto& ws) {
          ws.binary(m->binary);
          ws.async_write(asio::buffer(*current_), [self = shared_from_this()](beast::error_code ec, std::size_t n) {
            self->writing_ = false;
            self->current_.reset();
            if (ec) {
              if (!self->closing_) self->leave();
              self->closing_ = true;
              return;
            }
            self->bytes_sent_ += n;
            ++self->messages_sent_;
            self->pump();
          });
        },
        ws_);
  }

  /// The TCP socket under the WebSocket (and TLS).
  tcp::socket& socket() {
    return std::visit([](auto& ws) -> tcp::socket& { return beast::get_lowest_layer(ws).socket(); }, ws_);
  }

  using Socket = std::variant<websocket::stream<PlainStream>, websocket::stream<TlsStream>>;
  Socket ws_;
  http::request<http::string_body> upgrade_;
  std::shared_ptr<WebServer::Impl> server_;
  std::uint64_t id_;
  Outbox outbox_;
  RateLimit limit_;
  beast::flat_buffer in_;
  std::shared_ptr<const std::string> current_;
  std::size_t station_ = 0;
  bool writing_ = false, closing_ = false, foxglove_ = false, accepted_ = false;
  FoxgloveSubscriptions subscriptions_;
  std::set<std::pair<std::size_t, std::uint32_t>> taken_;  ///< (station, instrument) this browser took over
  std::uint64_t bytes_sent_ = 0, messages_sent_ = 0, errors_sent_ = 0, refused_in_a_row_ = 0;
  std::string address_;
  std::chrono::steady_clock::time_point opened_ = std::chrono::steady_clock::now();
};

void open_browser(Transport&& stream, std::shared_ptr<WebServer::Impl> server, http::request<http::string_body>&& upgrade, std::size_t station,
                  bool foxglove) {
  const std::uint64_t id = server->next_id++;
  std::make_shared<Browser>(std::move(stream), std::move(server), id)->start(std::move(upgrade), station, foxglove);
}

void WebServer::Impl::accept() {
  acceptor.async_accept([self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
    if (self->stopped) return;
    if (!ec) serve_http(std::move(socket), self);
    self->accept();
  });
}

bool WebServer::Impl::authorised(const http::request<http::string_body>& req, bool* from_query) const {
  const std::string_view target(req.target().data(), req.target().size());
  const auto q = target.find('?');
  const std::string query = q == std::string_view::npos ? std::string() : std::string(target.substr(q + 1));
  const std::string given = field_value(query, "token", '&');
  if (!given.empty()) {
    *from_query = token_matches(given, opt.token);
    return *from_query;
  }
  const auto cookie = req.find(http::field::cookie);
  return cookie != req.end() &&
         token_matches(field_value(std::string_view(cookie->value().data(), cookie->value().size()), "viscera_token", ';'), opt.token);
}

void WebServer::Impl::add_station(Station* s) {
  stations.push_back(s);
  latched.resize(stations.size());
  nlohmann::json names = nlohmann::json::array();
  for (const Station* x : stations) names.push_back(x->name());
  for (auto& [id, b] : std::map(browsers))
    if (!b->foxglove()) b->send_json({{"type", "stations"}, {"stations", names}});
}

void WebServer::add_station(Station* station) { impl_->add_station(station); }

nlohmann::json WebServer::Impl::stats() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [id, b] : browsers) list.push_back(b->stats());
  nlohmann::json st = nlohmann::json::array();
  for (const Station* s : stations) {
    const auto [p50, p99] = s->frame_delay_ms();
    st.push_back({{"name", s->name()}, {"rejected_payloads", s->rejected()}, {"frame_delay_ms", {{"p50", p50}, {"p99", p99}}}});
  }
  return {{"uptime_s", seconds_since(start)},
          {"browsers", list},
          {"stations", st},
          {"http_requests", counters.http_requests},
          {"refused_unauthorised", counters.refused},
          {"not_found", counters.not_found},
          {"browsers_opened", counters.browsers_opened},
          {"malformed_requests", counters.malformed},
          {"rate_limited_requests", counters.rate_limited},
          {"closed_oversized", counters.oversized},
          {"closed_slow", counters.closed_slow},
          {"closed_flood", counters.closed_flood},
          {"busy_refusals", counters.busy},
          {"tls", opt.tls != nullptr},
          {"tls_handshakes_failed", counters.tls_failed},
          {"plain_http_refused", counters.plain_refused}};
}

WebServer::WebServer(asio::io_context& io, const tcp::endpoint& listen, WebOptions options, std::vector<Station*> stations)
    : impl_(std::make_shared<Impl>(io, listen, std::move(options), std::move(stations))) {
  impl_->accept();
}

WebServer::~WebServer() {
  impl_->stopped = true;
  beast::error_code ec;
  impl_->acceptor.close(ec);
  for (auto& [id, b] : std::map(impl_->browsers)) b->close_now();
}

tcp::endpoint WebServer::endpoint() const { return impl_->acceptor.local_endpoint(); }

void WebServer::post_frame(std::size_t station, std::shared_ptr<const std::string> frame) {
  asio::post(impl_->io, [impl = impl_, station, frame = std::move(frame)] {
    for (auto& [id, b] : std::map(impl->browsers))
      if (b->station() == station && !b->foxglove()) b->send_frame(frame);  // the page's protocol only
  });
}

void WebServer::post_message(std::size_t station, OutMessage m) {
  asio::post(impl_->io, [impl = impl_, station, m = std::move(m)] {
    for (auto& [id, b] : std::map(impl->browsers))
      if (b->station() == station && !b->foxglove()) b->send(m);  // the page's protocol only
  });
}

nlohmann::json WebServer::stats() const { return impl_->stats(); }

bool WebServer::wants_raw() const { return impl_->foxglove_browsers > 0; }

void WebServer::post_raw(std::size_t station, protocol::Stream stream, std::int64_t stamp_ns,
                         std::shared_ptr<const std::vector<std::uint8_t>> payload) {
  asio::post(impl_->io, [impl = impl_, station, stream, stamp_ns, payload = std::move(payload)] {
    if (protocol::stream_info(stream).state) impl->latched[station][stream] = {stamp_ns, payload};
    for (auto& [id, b] : std::map(impl->browsers))
      if (b->station() == station) b->send_raw(stream, stamp_ns, *payload);
  });
}

}  // namespace viscera::console
