#include "play.hpp"

#include <chrono>
#include <cstdio>
#include <deque>
#include <map>
#include <thread>

#include <unistd.h>

#include <poll.h>
#include <termios.h>

#include "viscera/client/stream_tap.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/protocol/streams.hpp"
#include "viscera/recording/playback_clock.hpp"
#include "viscera/recording/recording.hpp"

namespace viscera::replay {

namespace proto = viscera::protocol;
namespace rec = viscera::recording;
using Clock = std::chrono::steady_clock;

namespace {

/// The terminal in raw mode while playing (single keys, no echo), restored after.
class RawTerminal {
 public:
  explicit RawTerminal(bool want) {
    if (!want || !isatty(0) || tcgetattr(0, &saved_) != 0) return;
    termios raw = saved_;
    raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(0, TCSANOW, &raw) == 0;
  }
  ~RawTerminal() {
    if (active_) tcsetattr(0, TCSANOW, &saved_);
  }
  bool active() const { return active_; }
  /// The keys typed since the last call.
  std::string keys() const {
    std::string out;
    if (!active_) return out;
    pollfd p{0, POLLIN, 0};
    while (poll(&p, 1, 0) > 0 && (p.revents & POLLIN)) {
      char b[16];
      const ssize_t n = read(0, b, sizeof b);
      if (n <= 0) break;
      out.append(b, static_cast<std::size_t>(n));
    }
    return out;
  }

 private:
  termios saved_{};
  bool active_ = false;
};

std::string seconds(std::uint64_t ns) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f s", 1e-9 * static_cast<double>(ns));
  return b;
}

}  // namespace

int play(const PlayOptions& o, const std::atomic<bool>& stop) {
  rec::Recording recording(o.recording);
  const std::uint64_t t0 = recording.start_ns(), t_end = recording.end_ns();
  const auto at = [&](double s) { return t0 + static_cast<std::uint64_t>(std::max(0.0, s) * 1e9); };
  if (at(o.from_s) > t_end)
    throw common::InputError(o.recording, 0, "--from",
                             seconds(at(o.from_s) - t0) + " is past the recording's end (it spans " + seconds(t_end - t0) + ")");
  const std::uint64_t from = at(o.from_s), to = o.to_s ? std::min(at(*o.to_s), t_end) : t_end;
  if (from > to) throw common::InputError(o.recording, 0, "--from/--to", "the interval is empty (the recording spans " + seconds(t_end - t0) + ")");
  const std::uint32_t domain = o.domain ? *o.domain : recording.domain_id();

  client::StreamPublisher publisher(domain, o.partition);
  client::StreamTap requests(domain, o.partition, {proto::Stream::session_request}, 64);
  // Writers for every stream the recording has, then a moment for the partition's clients to be
  // discovered: a volatile sample written before a reader is known never reaches it.
  std::map<proto::Stream, bool> streams;
  for (const auto& [id, ch] : recording.channels()) streams[ch.stream] = true;
  for (const auto& [s, _] : streams) publisher.open(s);
  publisher.wait_for_readers(std::chrono::milliseconds(static_cast<long long>(o.discovery_s * 1000)));
  const std::string live_server = "station '" + common::printable(o.partition, 80) +
                                  "' holds a live viscera-server: a replay never drives one (choose a station name of its own)";
  if (publisher.live_server()) throw common::InputError("--station", 0, "", live_server);

  // The scene state the replay shows: the recording's newest, with the playback's pause and the
  // outcomes of the requests sent to the replayer.
  std::optional<proto::Scene> scene;
  std::deque<proto::RequestOutcome> outcomes;
  rec::PlaybackClock clock(from, o.rate, Clock::now());
  const auto publish_scene = [&] {
    if (!scene) return;
    proto::Scene s = *scene;
    s.paused = s.paused || clock.paused();
    s.recent_requests.insert(s.recent_requests.end(), outcomes.begin(), outcomes.end());
    publisher.publish(proto::Stream::scene_state, 0, proto::encode(s));
  };
  // What a client joining at recording time `t` must have: the newest sample of each state stream
  // (scene state, surface topology, scene files) before it.
  const auto prime = [&](std::uint64_t t) {
    std::map<std::pair<proto::Stream, std::uint32_t>, std::vector<std::uint8_t>> last;
    recording.for_each(
        [&](const rec::RecordedChannel& ch, const mcap::Message& m) {
          if (proto::stream_info(ch.stream).state) last[{ch.stream, ch.source_id}] = m.data;
          return true;
        },
        t0, t);
    std::string why;
    for (const auto& [key, payload] : last) {
      if (key.first == proto::Stream::scene_state) {
        scene = proto::decode_scene(payload, &why);
        publish_scene();
      } else {
        publisher.publish(key.first, key.second, payload);
      }
    }
  };

  RawTerminal terminal(o.keys);
  if (!o.quiet) {
    std::printf("viscera-replay: playing %s (%s) from %s to %s at %gx onto DDS domain %u, station '%s'%s\n", o.recording.c_str(),
                seconds(t_end - t0).c_str(), seconds(from - t0).c_str(), seconds(to - t0).c_str(), o.rate, domain, o.partition.c_str(),
                terminal.active() ? "; keys: space pause/resume, left/right seek 5 s, q quit" : "");
    std::fflush(stdout);
  }
  prime(from);
  bool quit = false;
  std::optional<std::uint64_t> seek_to;
  const auto clamp = [&](std::int64_t t) {
    return static_cast<std::uint64_t>(std::clamp<std::int64_t>(t, static_cast<std::int64_t>(from), static_cast<std::int64_t>(to)));
  };
  // Keys and session requests: pause, resume, seek, quit; and a server that joins the partition.
  bool server_joined = false;
  auto server_checked = Clock::now();
  const auto handle_input = [&] {
    const auto now = Clock::now();
    if (now - server_checked >= std::chrono::milliseconds(100)) {
      server_checked = now;
      server_joined = publisher.live_server();
      quit = quit || server_joined;
    }
    const std::string keys = terminal.keys();
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const char k = keys[i];
      if (k == 'q') quit = true;
      if (k == ' ') clock.paused() ? clock.resume(now) : clock.pause(now);
      if (k == '\x1b' && i + 2 < keys.size() && keys[i + 1] == '[') {
        const std::int64_t pos = static_cast<std::int64_t>(clock.position(now));
        if (keys[i + 2] == 'C') seek_to = clamp(pos + 5'000'000'000);
        if (keys[i + 2] == 'D') seek_to = clamp(pos - 5'000'000'000);
        i += 2;
      }
    }
    bool changed = false;
    requests.take([&](const client::TapSample& s) {
      std::string why;
      const auto r = proto::decode_session_request(s.payload, &why);
      if (!r) return;
      proto::RequestOutcome out{r->client_id, r->request_seq, r->action, true, ""};
      switch (r->action) {
        case proto::Action::pause:
          clock.pause(now);
          out.message = "replay paused at " + seconds(clock.position(now) - t0);
          break;
        case proto::Action::resume:
          clock.resume(now);
          out.message = "replay resumed at " + seconds(clock.position(now) - t0);
          break;
        case proto::Action::seek:
          seek_to = clamp(static_cast<std::int64_t>(at(r->seek_s)));
          out.message = "replay sought to " + seconds(*seek_to - t0);
          break;
        default:
          out.accepted = false;
          out.message = std::string("a replay cannot ") + proto::action_name(r->action) + " (it plays a recording; control a live server instead)";
      }
      outcomes.push_back(out);
      while (outcomes.size() > 8) outcomes.pop_front();
      changed = true;
    });
    if (changed) publish_scene();
  };

  std::uint64_t published = 0, cursor = from;
  auto last_status = Clock::now();
  const auto wall_start = Clock::now();
  while (!quit && !stop.load()) {
    recording.for_each(
        [&](const rec::RecordedChannel& ch, const mcap::Message& m) {
          for (;;) {
            handle_input();
            if (quit || seek_to || stop.load()) return false;
            const auto now = Clock::now();
            const auto due = clock.due(m.log_time);
            if (now >= due) break;
            std::this_thread::sleep_for(std::min<Clock::duration>(due - now, std::chrono::milliseconds(10)));
          }
          if (ch.stream == proto::Stream::scene_state) {
            std::string why;
            if (auto s = proto::decode_scene(m.data, &why)) scene = std::move(s);
            publish_scene();
          } else {
            publisher.publish(ch.stream, ch.source_id, m.data);
          }
          ++published;
          cursor = m.log_time;
          if (!o.quiet && Clock::now() - last_status >= std::chrono::seconds(1)) {
            last_status = Clock::now();
            std::printf("viscera-replay: %s of %s%s, %llu messages\n", seconds(cursor - t0).c_str(), seconds(to - t0).c_str(),
                        clock.paused() ? " (paused)" : "", static_cast<unsigned long long>(published));
            std::fflush(stdout);
          }
          return true;
        },
        cursor, to);
    if (quit || stop.load()) break;
    if (seek_to) {
      cursor = *seek_to;
      seek_to.reset();
      clock.seek(cursor, Clock::now());
      prime(cursor);
      continue;
    }
    if (!o.loop) break;
    cursor = from;
    clock.seek(from, Clock::now());
    prime(from);
  }
  if (!o.quiet)
    std::printf("viscera-replay: published %llu messages in %.1f s\n", static_cast<unsigned long long>(published),
                std::chrono::duration<double>(Clock::now() - wall_start).count());
  if (server_joined) {
    std::fprintf(stderr, "viscera-replay: stopped: %s\n", live_server.c_str());
    return 3;
  }
  return 0;
}

}  // namespace viscera::replay
