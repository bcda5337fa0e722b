// viscera-console: the instructor's console in the browser. A client of the DDS domain (through  // SPDX-License-Identifier: Apache-2.0
// the client SDK) that serves the console page and a WebSocket to browsers: the organ's surface
// live, instruments, forces, health and events out; pause, resume, reset, load a scene, change the
// material, annotate and bookmark in (docs/CONSOLE.md).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <thread>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/common/program_log.hpp"
#include "viscera/console/access_token.hpp"
#include "viscera/console/tls_context.hpp"
#include "viscera/process/child_process.hpp"
#include "viscera/protocol/dds.hpp"

#include "station.hpp"
#include "web_server.hpp"

#ifndef VISCERA_CONSOLE_WEB_DIR
#define VISCERA_CONSOLE_WEB_DIR ""
#endif

namespace {

namespace asio = boost::asio;
using viscera::common::UsageError;

/// "ADDRESS:PORT" (an IPv6 address in brackets: "[::1]:8080").
asio::ip::tcp::endpoint parse_listen(const std::string& s) {
  const auto colon = s.rfind(':');
  if (colon == std::string::npos) throw UsageError("--listen '" + s + "' is not ADDRESS:PORT");
  std::string host = s.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(host, ec);
  if (ec) throw UsageError("--listen '" + s + "': '" + host + "' is not an IP address");
  std::string why;
  const auto port = viscera::common::read_integer(std::string_view(s).substr(colon + 1), &why);
  if (!port) throw UsageError("--listen '" + s + "': port " + why);
  if (*port < 0 || *port > 65535) throw UsageError("--listen '" + s + "': port " + viscera::common::outside(*port, 0LL, 65535LL));
  return {address, static_cast<unsigned short>(*port)};
}

/// The page's files from the web folder the build made (index.html, console.js, console.css).
std::map<std::string, std::string> read_page(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const char* name : {"index.html", "console.js", "console.css"}) {
    const std::string path = dir + "/" + name;
    if (!std::filesystem::exists(path))
      throw viscera::common::InputError(dir, 0, "--web-root",
                                        std::string(name) + " is missing (the build makes it from tools/viscera-console/web: npm ci there)");
    files["/" + std::string(name)] = viscera::common::read_text_file(path, 16u << 20);
  }
  return files;
}

std::vector<std::string> split(const std::string& s, char c) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string part; std::getline(in, part, c);) out.push_back(part);
  if (s.empty() || s.back() == c) out.emplace_back();
  return out;
}

/// Opens recordings for replay: each plays in a viscera-replay process of its own, in a partition
/// of its own, its log in a folder of this console's (made with mkdtemp, removed at the end).
class ReplayLauncher {
 public:
  ReplayLauncher(std::string replayer, std::string recordings_dir, std::uint32_t domain)
      : replayer_(std::move(replayer)), recordings_dir_(std::move(recordings_dir)), domain_(domain) {
    // A fresh name, mode 0700: never a path in /tmp that another user could have linked elsewhere.
    std::string tmpl = (std::filesystem::temp_directory_path() / "viscera-console-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("cannot make a folder for the replays' logs in " + tmpl);
    log_dir_ = tmpl;
  }
  ReplayLauncher(const ReplayLauncher&) = delete;
  ReplayLauncher& operator=(const ReplayLauncher&) = delete;
  ~ReplayLauncher() {
    replays_.clear();  // stopped before their logs go
    std::error_code ec;
    std::filesystem::remove_all(log_dir_, ec);
  }

  /// Starts a replay of `file` (in the recordings folder); its partition, or empty with `why`.
  std::string start(const std::string& file, std::string* why) {
    // A replay that ended (played out, or failed) frees its slot.
    std::erase_if(replays_, [](const auto& r) { return !r->alive(); });
    if (replays_.size() >= 4) {
      *why = "4 replays are playing already (one must end first)";
      return {};
    }
    std::string partition = "viscera-replay-" + std::to_string(++opened_);
    log_ = (std::filesystem::path(log_dir_) / (partition + ".log")).string();
    try {
      replays_.push_back(std::make_unique<viscera::process::ChildProcess>(
          std::vector<std::string>{replayer_, "play", recordings_dir_ + "/" + file, "--station", partition, "--domain", std::to_string(domain_),
                                   "--no-keys", "--quiet"},
          log_));
    } catch (const std::exception& e) {
      *why = e.what();
      return {};
    }
    // A recording the replayer refuses (empty, damaged, not MCAP) makes it exit at once: its own
    // one-line error goes to the page, and nothing is left behind.
    for (int k = 0; k < 40 && replays_.back()->alive(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!replays_.back()->alive()) {
      *why = replays_.back()->log_tail(1);
      if (why->empty()) *why = "the replayer stopped at once";
      replays_.pop_back();
      return {};
    }
    return partition;
  }
  /// The log of the replay started last.
  const std::string& last_log() const { return log_; }

 private:
  std::string replayer_, recordings_dir_, log_dir_, log_;
  std::uint32_t domain_;
  std::vector<std::unique_ptr<viscera::process::ChildProcess>> replays_;
  std::size_t opened_ = 0;
};

/// The console's stations (given, opened as replays, or discovered), each one's messages posted to
/// the web server once it runs.
class Stations {
 public:
  Stations(std::uint32_t domain, std::uint32_t client_id, double force_period_s)
      : domain_(domain), client_id_(client_id), force_period_s_(force_period_s) {}
  viscera::console::Station* add(const std::string& partition) {
    const std::size_t k = stations_.size();
    stations_.push_back(std::make_unique<viscera::console::Station>(domain_, partition, client_id_, force_period_s_, sink(k)));
    return stations_.back().get();
  }
  bool has(const std::string& name) const {
    return std::any_of(stations_.begin(), stations_.end(), [&](const auto& s) { return s->name() == name; });
  }
  std::vector<viscera::console::Station*> list() const {
    std::vector<viscera::console::Station*> out;
    for (const auto& s : stations_) out.push_back(s.get());
    return out;
  }
  std::size_t size() const { return stations_.size(); }
  void attach(viscera::console::WebServer* web) { web_ = web; }

 private:
  viscera::console::StationSink sink(std::size_t k) {
    return viscera::console::StationSink{
        [this, k](std::shared_ptr<const std::string> f) {
          if (auto* w = web_.load()) w->post_frame(k, std::move(f));
        },
        [this, k](viscera::console::OutMessage m) {
          if (auto* w = web_.load()) w->post_message(k, std::move(m));
        },
        [this, k](viscera::protocol::Stream s, std::int64_t stamp, std::shared_ptr<const std::vector<std::uint8_t>> p) {
          if (auto* w = web_.load()) w->post_raw(k, s, stamp, std::move(p));
        },
        [this] {
          auto* w = web_.load();
          return w != nullptr && w->wants_raw();
        }};
  }

  std::uint32_t domain_, client_id_;
  double force_period_s_;
  std::atomic<viscera::console::WebServer*> web_{nullptr};
  std::vector<std::unique_ptr<viscera::console::Station>> stations_;
};

void define_flags(viscera::common::CommandLine& cl) {
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("stations", "P1,P2", "the stations to offer, as DDS partitions (a trainee station's server in each; empty: the default partition)", "");
  cl.option_switch("discover", "also offer a station for every partition in which a viscera server appears on the domain (looked for every second)");
  cl.flag("listen", "ADDRESS:PORT",
          "where browsers connect (port 0: any free one); another address than loopback makes the console remote, and needs --tls-cert",
          "127.0.0.1:8080");
  cl.flag("tls-cert", "FILE", "serve HTTPS and WSS with this PEM certificate chain (the console's certificate first; plain HTTP: loopback only)");
  cl.flag("tls-key", "FILE", "the private key of --tls-cert (PEM; mode 600)");
  cl.flag("token-file", "FILE", "the access token's file (one line, at least 32 characters: openssl rand -hex 16 > FILE)");
  cl.flag("web-root", "DIR", "the page's files (built by the project's build)", VISCERA_CONSOLE_WEB_DIR);
  cl.flag("client-id", "N", "the console's client id on the domain", "950");
  cl.flag("force-limit-n", "N", "the safe force limit drawn on the force plot [N]", "3");
  cl.flag("force-rate-hz", "HZ", "force summaries per second and instrument sent to browsers (the peak of each period kept)", "30");
  cl.flag("outbox-kib", "KIB", "what may wait for one browser before its oldest forces and telemetry are dropped [KiB]", "4096");
  cl.flag("requests-per-s", "R", "requests a browser may send a second (bursts of twice that)", "20");
  cl.flag("recordings", "DIR", "session recordings (viscera-record) a browser may open for replay, each as a station of its own (none: no replays)");
  cl.flag("allow-origin", "ORIGIN,...", "WebSocket origins allowed besides the console's own address (a proxy's https://HOST, a Foxglove web app)",
          "");
  cl.flag("replayer", "PATH", "the viscera-replay program (default: the one beside this program)");
  cl.flag("stats-every-s", "S", "print the browsers' traffic every S seconds (0: never)", "0");
  cl.flag("log-file", "FILE", "append the log's lines to this file too (a service's log)", "");
}

/// What the web server takes from the command line: the token, TLS, the page, origins and limits.
viscera::console::WebOptions web_options(const viscera::common::CommandLine& cl, bool tls, spdlog::logger& logger) {
  viscera::console::WebOptions options;
  options.token = viscera::console::read_token_file(cl.text("token-file"));
  if (const auto w = viscera::console::token_file_warning(cl.text("token-file")); !w.empty()) logger.warn("{}", w);
  if (tls) {
    options.tls = viscera::console::make_tls_context(cl.text("tls-cert"), cl.text("tls-key"));
    if (const auto w = viscera::console::token_file_warning(cl.text("tls-key"), "anyone who reads it can pose as this console"); !w.empty())
      logger.warn("{}", w);
  }
  options.files = read_page(cl.text("web-root"));
  options.allowed_origins = split(cl.text("allow-origin"), ',');
  options.outbox_bytes = static_cast<std::size_t>(1024 * cl.number_in("outbox-kib", 64, 1 << 20));
  options.requests_per_s = cl.number_in("requests-per-s", 1, 1000);
  options.request_burst = 2 * options.requests_per_s;
  return options;
}

/// --discover: a station for every partition where a server's scene state appears (DDS discovery,
/// looked at every second), unless one is offered already (given, a replay, or found before).
void discover_every_second(Stations& stations, viscera::protocol::PartitionDiscovery& discovery, viscera::console::WebServer& server,
                           boost::asio::steady_timer& timer, spdlog::logger& logger) {
  for (const std::string& partition : discovery.take_new()) {
    const std::string name = partition.empty() ? "default" : partition;
    if (stations.has(name)) continue;
    server.add_station(stations.add(partition));
    logger.info("a server appeared in partition {}: offered as station {}", name, name);
  }
  timer.expires_after(std::chrono::seconds(1));
  timer.async_wait([&](const boost::system::error_code& e) {
    if (!e) discover_every_second(stations, discovery, server, timer, logger);
  });
}

/// --stats-every-s: the browsers' traffic in the log.
void print_stats_every(double period_s, viscera::console::WebServer& server, boost::asio::steady_timer& timer, spdlog::logger& logger) {
  timer.expires_after(std::chrono::milliseconds(static_cast<long>(1000 * period_s)));
  timer.async_wait([&, period_s](const boost::system::error_code& ec) {
    if (ec) return;
    const auto s = server.stats();
    for (const auto& b : s["browsers"])
      logger.info("browser {}: {:.0f} B/s, {} frames skipped, {} KiB waiting", b["address"].get<std::string>(), b["bytes_per_s"].get<double>(),
                  b["frames_skipped"].dump(), b["queued_bytes"].get<std::size_t>() / 1024);
    print_stats_every(period_s, server, timer, logger);
  });
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl("viscera-console",
                                  "The instructor's console: serves a web page that shows a running viscera-server live (the organ deforming, the\n"
                                  "instruments and their forces, health, events) and steers it (pause, resume, reset, load a scene, change the\n"
                                  "material, annotate, bookmark). Open the address it prints; it carries the access token.");
  define_flags(cl);
  std::shared_ptr<spdlog::logger> logger;  // once the command line is read
  const auto fail = [&](const std::string& message) {
    if (logger)
      logger->error("{}", message);
    else
      std::fprintf(stderr, "viscera-console: %s\n", message.c_str());
  };
  try {
    if (!cl.parse(argc, argv)) return 0;
    if (!cl.has("token-file")) throw UsageError("--token-file is required (the access token: openssl rand -hex 16 > FILE)");
    const auto listen = parse_listen(cl.text("listen"));
    if (cl.has("tls-cert") != cl.has("tls-key")) throw UsageError("--tls-cert and --tls-key go together (the certificate and its private key)");
    const bool tls = cl.has("tls-cert");
    // The token travels in every request: beyond this host only encrypted.
    if (!tls && !listen.address().is_loopback())
      throw UsageError("--listen " + cl.text("listen") +
                       " is not a loopback address: a console other hosts reach serves HTTPS only (--tls-cert FILE --tls-key FILE; "
                       "deploy/dds/make-test-pki.sh makes a test pair, docs/DEPLOY.md)");
    std::vector<std::string> inputs{cl.text("token-file")};
    if (tls) inputs.insert(inputs.end(), {cl.text("tls-cert"), cl.text("tls-key")});
    logger = viscera::common::program_log("viscera-console", cl.text("log-file"), inputs);
    viscera::console::WebOptions options = web_options(cl, tls, *logger);
    const std::string token = options.token;
    const auto domain = static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230));
    const auto client_id = static_cast<std::uint32_t>(cl.integer_in("client-id", 1, 4000000000));
    options.page_settings = {{"force_limit_n", cl.number_in("force-limit-n", 0.01, 1000)}, {"client_id", client_id}};
    const double force_period_s = 1.0 / cl.number_in("force-rate-hz", 1, 1000);
    const double stats_every_s = cl.number_in("stats-every-s", 0, 3600);

    asio::io_context io(1);
    Stations stations(domain, client_id, force_period_s);
    for (const auto& p : split(cl.text("stations"), ',')) stations.add(viscera::protocol::checked_station(p, "--stations"));
    // Replays opened from the page (called on the web server's thread), stopped with the console.
    std::optional<ReplayLauncher> replays;
    if (cl.has("recordings")) {
      options.recordings_dir = cl.text("recordings");
      if (!std::filesystem::is_directory(options.recordings_dir))
        throw viscera::common::InputError(options.recordings_dir, 0, "--recordings", "is not a folder");
      replays.emplace(cl.has("replayer") ? cl.text("replayer") : viscera::process::find_program("viscera-replay", "tools/viscera-replay"),
                      options.recordings_dir, domain);
      options.open_replay = [&](const std::string& file, std::string* why) -> viscera::console::Station* {
        const std::string partition = replays->start(file, why);
        if (partition.empty()) return nullptr;
        logger->info("replaying {} as station {} (log {})", file, partition, replays->last_log());
        return stations.add(partition);
      };
    }
    auto server = std::make_unique<viscera::console::WebServer>(io, listen, std::move(options), stations.list());
    stations.attach(server.get());
    const auto ep = server->endpoint();
    const std::string host = ep.address().is_v6() ? "[" + ep.address().to_string() + "]" : ep.address().to_string();
    // The token is a secret: never in a log (the unit sends this line to the journal and a log file).
    logger->info("domain {}, {} station(s); open {}://{}:{}/ with ?token= and the token in {} (it is never logged)", domain, stations.size(),
                 tls ? "https" : "http", host, ep.port(), cl.text("token-file"));

    std::optional<viscera::protocol::Participant> discovery_participant;
    std::optional<viscera::protocol::PartitionDiscovery> discovery;
    asio::steady_timer discovery_timer(io);
    if (cl.has("discover")) {
      discovery_participant.emplace(domain);
      discovery.emplace(*discovery_participant, viscera::protocol::Stream::scene_state);
      discover_every_second(stations, *discovery, *server, discovery_timer, *logger);
    }
    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code&, int) { io.stop(); });
    asio::steady_timer stats_timer(io);
    if (stats_every_s > 0) print_stats_every(stats_every_s, *server, stats_timer, *logger);
    io.run();
    stations.attach(nullptr);
    server.reset();
    logger->info("stopped");
    return 0;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-console: %s\n", e.what());
    return 2;
  } catch (const viscera::common::InputError& e) {
    fail(e.what());
    return 2;
  } catch (const boost::system::system_error& e) {
    fail("cannot listen on " + cl.text("listen") + ": " + e.code().message());
    return 2;
  } catch (const std::exception& e) {
    fail(e.what());
    return 1;
  }
}
