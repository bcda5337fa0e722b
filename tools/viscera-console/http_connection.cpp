#include <cstring>  // SPDX-License-Identifier: Apache-2.0

#include <boost/beast/core/detect_ssl.hpp>
#include <boost/beast/websocket.hpp>

#include "viscera/common/input_error.hpp"
#include "viscera/console/access_token.hpp"
#include "viscera/console/foxglove_protocol.hpp"

#include "web_server_impl.hpp"

namespace viscera::console {

namespace websocket = beast::websocket;

namespace {

const char* content_type(const std::string& path) {
  const auto ends = [&](const char* e) {
    return path.size() >= std::strlen(e) && path.compare(path.size() - std::strlen(e), std::string::npos, e) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".png")) return "image/png";
  if (ends(".svg")) return "image/svg+xml";
  return "application/octet-stream";
}

/// One HTTP connection: requests for the page's files, /stats, or the upgrade to a WebSocket.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(Transport stream, std::shared_ptr<WebServer::Impl> server) : stream_(std::move(stream)), server_(std::move(server)) {}

  /// A console with TLS: the first bytes say whether the client speaks TLS; a plain HTTP request
  /// is told where to go, a TLS client gets the handshake (10 s at most), then its requests are read.
  void handshake() {
    auto& plain = std::get<PlainStream>(stream_);
    plain.expires_after(std::chrono::seconds(10));
    beast::async_detect_ssl(plain, buffer_, [self = shared_from_this()](beast::error_code ec, bool tls) {
      if (ec) return;
      if (!tls) return self->refuse_plain();
      auto& server = *self->server_;
      PlainStream tcp_stream = std::move(std::get<PlainStream>(self->stream_));
      self->stream_.emplace<TlsStream>(std::move(tcp_stream), *server.opt.tls);
      std::get<TlsStream>(self->stream_)
          .async_handshake(asio::ssl::stream_base::server, self->buffer_.data(), [self](beast::error_code e, std::size_t used) {
            self->buffer_.consume(used);
            if (e) {
              ++self->server_->counters.tls_failed;  // a client that refused the certificate, or a timeout
              return;
            }
            self->read();
          });
    });
  }

  /// A plain HTTP request on a console that speaks HTTPS only.
  void refuse_plain() {
    ++server_->counters.plain_refused;
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(16 * 1024);
    http::async_read(std::get<PlainStream>(stream_), buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return;
      const auto req = self->parser_->release();
      self->respond(req, http::status::bad_request, "text/plain", "this console speaks HTTPS only: open its address with https://\n", false);
    });
  }

  void read() {
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(16 * 1024);
    std::visit(
        [this](auto& s) {
          beast::get_lowest_layer(s).expires_after(std::chrono::seconds(30));
          http::async_read(s, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
        },
        stream_);
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec) return;  // closed, timed out, or a request over the limits: the connection ends
    auto req = parser_->release();
    ++server_->counters.http_requests;
    bool from_query = false;
    const bool ok = server_->authorised(req, &from_query);
    if (websocket::is_upgrade(req)) {
      const std::string target(req.target());
      if (!ok) return respond(req, http::status::unauthorized, "text/plain", "the console's token is missing or wrong\n", false);
      const auto origin = req.find(http::field::origin);
      const auto host = req.find(http::field::host);
      const std::string_view origin_text =
          origin == req.end() ? std::string_view() : std::string_view(origin->value().data(), origin->value().size());
      if (!origin_allowed(origin_text, host == req.end() ? std::string_view() : std::string_view(host->value().data(), host->value().size()),
                          server_->opt.allowed_origins)) {
        ++server_->counters.refused;
        return respond(req, http::status::forbidden, "text/plain",
                       "origin '" + common::printable(origin_text, 100) + "' is not this console's (viscera-console --allow-origin)\n", false);
      }
      const std::string path = target.substr(0, target.find('?'));
      if (path != "/ws" && path != "/") return respond(req, http::status::not_found, "text/plain", "no WebSocket here (/ws)\n", false);
      if (server_->browsers.size() >= server_->opt.max_browsers)
        return respond(req, http::status::service_unavailable, "text/plain", "too many browsers\n", false);
      std::visit([](auto& s) { beast::get_lowest_layer(s).expires_never(); }, stream_);
      // A Foxglove client asks for its subprotocol; ?station=NAME picks the station (default: the first).
      const auto protocols = req.find(http::field::sec_websocket_protocol);
      const bool foxglove = protocols != req.end() && protocols->value().find(kFoxgloveSubprotocol) != beast::string_view::npos;
      const std::string query = target.find('?') == std::string::npos ? std::string() : target.substr(target.find('?') + 1);
      const std::string wanted = field_value(query, "station", '&');
      std::size_t station = 0;
      for (std::size_t k = 0; k < server_->stations.size(); ++k)
        if (server_->stations[k]->name() == wanted) station = k;
      if (!wanted.empty() && server_->stations[station]->name() != wanted)
        return respond(req, http::status::not_found, "text/plain", "no station '" + wanted.substr(0, 64) + "'\n", false);
      open_browser(std::move(stream_), server_, std::move(req), station, foxglove);
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return respond(req, http::status::method_not_allowed, "text/plain", "only GET\n", false);
    if (!ok)
      return respond(req, http::status::unauthorized, "text/html; charset=utf-8",
                     "<!doctype html><title>viscera console</title><p>This console needs its access token: open the address the console "
                     "printed when it started (it ends in <code>?token=...</code>).</p>\n",
                     false);
    std::string path(req.target().substr(0, req.target().find('?')));
    if (path == "/") path = "/index.html";
    if (path == "/stats") return respond(req, http::status::ok, "application/json", server_->stats().dump(1) + "\n", from_query);
    const auto f = server_->opt.files.find(path);
    if (f == server_->opt.files.end()) {
      ++server_->counters.not_found;
      return respond(req, http::status::not_found, "text/plain", "not found\n", from_query);
    }
    respond(req, http::status::ok, content_type(path), f->second, from_query);
  }

  void respond(const http::request<http::string_body>& req, http::status status, const char* type, std::string body, bool set_cookie) {
    if (status == http::status::unauthorized) ++server_->counters.refused;
    auto res = std::make_shared<http::response<http::string_body>>(status, req.version());
    res->set(http::field::server, "viscera-console");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-store");
    res->set("X-Content-Type-Options", "nosniff");
    if (set_cookie)
      res->set(http::field::set_cookie,
               "viscera_token=" + server_->opt.token + "; HttpOnly; SameSite=Strict; Path=/" + (server_->opt.tls ? "; Secure" : ""));
    res->keep_alive(req.keep_alive() && status == http::status::ok);
    res->body() = req.method() == http::verb::head ? std::string() : std::move(body);
    res->prepare_payload();
    std::visit(
        [this, res](auto& s) {
          http::async_write(s, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
            if (ec || !res->keep_alive()) return self->close();
            self->read();
          });
        },
        stream_);
  }

  /// The end of the conversation: TLS says so first (close_notify, 5 s at most), then TCP.
  void close() {
    const auto tcp_close = [](PlainStream& s) {
      beast::error_code ignored;
      s.socket().shutdown(tcp::socket::shutdown_send, ignored);
    };
    if (auto* plain = std::get_if<PlainStream>(&stream_)) return tcp_close(*plain);
    auto& tls = std::get<TlsStream>(stream_);
    beast::get_lowest_layer(tls).expires_after(std::chrono::seconds(5));
    tls.async_shutdown(
        [self = shared_from_this(), tcp_close](beast::error_code) { tcp_close(beast::get_lowest_layer(std::get<TlsStream>(self->stream_))); });
  }

  Transport stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<WebServer::Impl> server_;
};

}  // namespace

void serve_http(tcp::socket socket, std::shared_ptr<WebServer::Impl> server) {
  const bool tls = server->opt.tls != nullptr;
  auto c = std::make_shared<HttpConnection>(Transport(std::in_place_type<PlainStream>, std::move(socket)), std::move(server));
  if (tls)
    c->handshake();
  else
    c->read();
}

}  // namespace viscera::console
