// viscera-console: the instructor's console in the browser. A client of the DDS domain (through
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

/// Removes a folder (if named) with what it holds when it goes out of scope.
struct RemoveAll {
  const std::string& path;
  explicit RemoveAll(const std::string& p) : path(p) {}
  RemoveAll(const RemoveAll&) = delete;
  RemoveAll& operator=(const RemoveAll&) = delete;
  ~RemoveAll() {
    std::error_code ec;
    if (!path.empty()) std::filesystem::remove_all(path, ec);
  }
};

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

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl("viscera-console",
                                  "The instructor's console: serves a web page that shows a running viscera-server live (the organ deforming, the\n"
                                  "instruments and their forces, health, events) and steers it (pause, resume, reset, load a scene, change the\n"
                                  "material, annotate, bookmark). Open the address it prints; it carries the access token.");
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
    viscera::console::WebOptions options;
    options.token = viscera::console::read_token_file(cl.text("token-file"));
    if (const auto w = viscera::console::token_file_warning(cl.text("token-file")); !w.empty()) logger->warn("{}", w);
    const std::string token = options.token;
    if (tls) {
      options.tls = viscera::console::make_tls_context(cl.text("tls-cert"), cl.text("tls-key"));
      if (const auto w = viscera::console::token_file_warning(cl.text("tls-key"), "anyone who reads it can pose as this console"); !w.empty())
        logger->warn("{}", w);
    }
    options.files = read_page(cl.text("web-root"));
    options.allowed_origins = split(cl.text("allow-origin"), ',');
    options.outbox_bytes = static_cast<std::size_t>(1024 * cl.number_in("outbox-kib", 64, 1 << 20));
    options.requests_per_s = cl.number_in("requests-per-s", 1, 1000);
    options.request_burst = 2 * options.requests_per_s;
    const auto domain = static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230));
    const auto client_id = static_cast<std::uint32_t>(cl.integer_in("client-id", 1, 4000000000));
    options.page_settings = {{"force_limit_n", cl.number_in("force-limit-n", 0.01, 1000)}, {"client_id", client_id}};
    const double force_period_s = 1.0 / cl.number_in("force-rate-hz", 1, 1000);
    const double stats_every_s = cl.number_in("stats-every-s", 0, 3600);

    asio::io_context io(1);
    std::atomic<viscera::console::WebServer*> web{nullptr};
    std::vector<std::unique_ptr<viscera::console::Station>> stations;
    std::vector<viscera::console::Station*> station_list;
    // Where a station's messages go: the web server, once it exists.
    const auto make_sink = [&web](std::size_t k) {
      return viscera::console::StationSink{
          [&web, k](std::shared_ptr<const std::string> f) {
            if (auto* w = web.load()) w->post_frame(k, std::move(f));
          },
          [&web, k](viscera::console::OutMessage m) {
            if (auto* w = web.load()) w->post_message(k, std::move(m));
          },
          [&web, k](viscera::protocol::Stream s, std::int64_t stamp, std::shared_ptr<const std::vector<std::uint8_t>> p) {
            if (auto* w = web.load()) w->post_raw(k, s, stamp, std::move(p));
          },
          [&web] {
            auto* w = web.load();
            return w != nullptr && w->wants_raw();
          }};
    };
    auto partitions = split(cl.text("stations"), ',');
    for (auto& p : partitions) p = viscera::protocol::checked_station(p, "--stations");
    for (std::size_t k = 0; k < partitions.size(); ++k) {
      stations.push_back(std::make_unique<viscera::console::Station>(domain, partitions[k], client_id, force_period_s, make_sink(k)));
      station_list.push_back(stations.back().get());
    }
    // Replays opened from the page: viscera-replay play in a partition of its own each, stopped
    // with the console. Called on the web server's thread.
    std::string log_dir;
    const RemoveAll remove_log_dir{log_dir};  // after the replays have stopped
    std::vector<std::unique_ptr<viscera::process::ChildProcess>> replays;
    std::size_t replays_opened = 0;
    const std::string replayer = cl.has("replayer") ? cl.text("replayer") : viscera::process::find_program("viscera-replay", "tools/viscera-replay");
    const std::string recordings_dir = cl.has("recordings") ? cl.text("recordings") : std::string();
    if (!recordings_dir.empty()) {
      options.recordings_dir = recordings_dir;
      if (!std::filesystem::is_directory(options.recordings_dir))
        throw viscera::common::InputError(options.recordings_dir, 0, "--recordings", "is not a folder");
      // The replays' logs in a folder of this console's own (mkdtemp: a fresh name, mode 0700),
      // never at a path in /tmp that another user could have linked elsewhere.
      std::string tmpl = (std::filesystem::temp_directory_path() / "viscera-console-XXXXXX").string();
      if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("cannot make a folder for the replays' logs in " + tmpl);
      log_dir = tmpl;
      options.open_replay = [&, domain, client_id, force_period_s](const std::string& file, std::string* why) -> viscera::console::Station* {
        // A replay that ended (played out, or failed) frees its slot.
        std::erase_if(replays, [](const auto& r) { return !r->alive(); });
        if (replays.size() >= 4) {
          *why = "4 replays are playing already (one must end first)";
          return nullptr;
        }
        const std::string partition = "viscera-replay-" + std::to_string(++replays_opened);
        const std::string log = (std::filesystem::path(log_dir) / (partition + ".log")).string();
        try {
          replays.push_back(std::make_unique<viscera::process::ChildProcess>(
              std::vector<std::string>{replayer, "play", recordings_dir + "/" + file, "--station", partition, "--domain", std::to_string(domain),
                                       "--no-keys", "--quiet"},
              log));
        } catch (const std::exception& e) {
          *why = e.what();
          return nullptr;
        }
        // A recording the replayer refuses (empty, damaged, not MCAP) makes it exit at once: its own
        // one-line error goes to the page, and nothing is left behind.
        for (int k = 0; k < 40 && replays.back()->alive(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (!replays.back()->alive()) {
          *why = replays.back()->log_tail(1);
          if (why->empty()) *why = "the replayer stopped at once";
          replays.pop_back();
          return nullptr;
        }
        const std::size_t k = stations.size();
        stations.push_back(std::make_unique<viscera::console::Station>(domain, partition, client_id, force_period_s, make_sink(k)));
        logger->info("replaying {} as station {} (log {})", file, partition, log);
        return stations.back().get();
      };
    }
    auto server = std::make_unique<viscera::console::WebServer>(io, listen, std::move(options), station_list);
    web = server.get();
    const auto ep = server->endpoint();
    const std::string host = ep.address().is_v6() ? "[" + ep.address().to_string() + "]" : ep.address().to_string();
    logger->info("domain {}, {} station(s); open {}://{}:{}/?token={}", domain, stations.size(), tls ? "https" : "http", host, ep.port(), token);

    // --discover: a station for every partition where a server's scene state appears (DDS
    // discovery), unless one is offered already (given, a replay opened here, or found before).
    std::optional<viscera::protocol::Participant> discovery_participant;
    std::optional<viscera::protocol::PartitionDiscovery> discovery;
    asio::steady_timer discovery_timer(io);
    std::function<void()> discover = [&] {
      for (const std::string& partition : discovery->take_new()) {
        const std::string name = partition.empty() ? "default" : partition;
        if (std::any_of(stations.begin(), stations.end(), [&](const auto& s) { return s->name() == name; })) continue;
        const std::size_t k = stations.size();
        stations.push_back(std::make_unique<viscera::console::Station>(domain, partition, client_id, force_period_s, make_sink(k)));
        server->add_station(stations.back().get());
        logger->info("a server appeared in partition {}: offered as station {}", name, name);
      }
      discovery_timer.expires_after(std::chrono::seconds(1));
      discovery_timer.async_wait([&](const boost::system::error_code& e) {
        if (!e) discover();
      });
    };
    if (cl.has("discover")) {
      discovery_participant.emplace(domain);
      discovery.emplace(*discovery_participant, viscera::protocol::Stream::scene_state);
      discover();
    }

    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code&, int) { io.stop(); });
    asio::steady_timer timer(io);
    std::function<void()> print_stats = [&] {
      timer.expires_after(std::chrono::milliseconds(static_cast<long>(1000 * stats_every_s)));
      timer.async_wait([&](const boost::system::error_code& ec) {
        if (ec) return;
        const auto s = server->stats();
        for (const auto& b : s["browsers"])
          logger->info("browser {}: {:.0f} B/s, {} frames skipped, {} KiB waiting", b["address"].get<std::string>(), b["bytes_per_s"].get<double>(),
                       b["frames_skipped"].dump(), b["queued_bytes"].get<std::size_t>() / 1024);
        print_stats();
      });
    };
    if (stats_every_s > 0) print_stats();
    io.run();
    web = nullptr;
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
