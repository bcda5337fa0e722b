#include "play.hpp"  // SPDX-License-Identifier: Apache-2.0

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
#include "viscera/protocol/surface_assembler.hpp"
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

/// One playback: the recording, the partition's writers, the scene state the replay shows (the
/// recording's newest, with the playback's pause and the outcomes of the requests sent to the
/// replayer), the clock, and the keys.
class Player {
 public:
  Player(const PlayOptions& o, const std::atomic<bool>& stop)
      : o_(o),
        stop_(stop),
        recording_(o.recording),
        t0_(recording_.start_ns()),
        t_end_(recording_.end_ns()),
        from_(at(o.from_s)),
        to_(o.to_s ? std::min(at(*o.to_s), t_end_) : t_end_),
        domain_(o.domain ? *o.domain : recording_.domain_id()),
        live_server_("station '" + common::printable(o.partition, 80) +
                     "' holds a live viscera-server: a replay never drives one (choose a station name of its own)") {
    if (from_ > t_end_)
      throw common::InputError(o.recording, 0, "--from",
                               seconds(from_ - t0_) + " is past the recording's end (it spans " + seconds(t_end_ - t0_) + ")");
    if (from_ > to_)
      throw common::InputError(o.recording, 0, "--from/--to", "the interval is empty (the recording spans " + seconds(t_end_ - t0_) + ")");
  }

  int run() {
    client::StreamPublisher publisher(domain_, o_.partition);
    client::StreamTap requests(domain_, o_.partition, {proto::Stream::session_request}, 64);
    publisher_ = &publisher;
    requests_ = &requests;
    // Writers for every stream the recording has, then a moment for the partition's clients to be
    // discovered: a volatile sample written before a reader is known never reaches it.
    std::map<proto::Stream, bool> streams;
    for (const auto& [id, ch] : recording_.channels()) streams[ch.stream] = true;
    for (const auto& [s, _] : streams) publisher.open(s);
    publisher.wait_for_readers(std::chrono::milliseconds(static_cast<long long>(o_.discovery_s * 1000)));
    if (publisher.live_server()) throw common::InputError("--station", 0, "", live_server_);

    RawTerminal terminal(o_.keys);
    terminal_ = &terminal;
    if (!o_.quiet) {
      std::printf("viscera-replay: playing %s (%s) from %s to %s at %gx onto DDS domain %u, station '%s'%s\n", o_.recording.c_str(),
                  seconds(t_end_ - t0_).c_str(), seconds(from_ - t0_).c_str(), seconds(to_ - t0_).c_str(), o_.rate, domain_, o_.partition.c_str(),
                  terminal.active() ? "; keys: space pause/resume, left/right seek 5 s, q quit" : "");
      std::fflush(stdout);
    }
    const auto wall_start = Clock::now();
    std::uint64_t cursor = from_;
    clock_.seek(cursor, wall_start);  // the playback starts now, after discovery
    prime(cursor);
    while (!quit_ && !stop_.load()) {
      cursor = play_until_interrupted(cursor);
      if (quit_ || stop_.load()) break;
      if (seek_to_) {
        cursor = *seek_to_;
        seek_to_.reset();
      } else if (o_.loop) {
        cursor = from_;
      } else {
        break;
      }
      clock_.seek(cursor, Clock::now());
      prime(cursor);
    }
    if (!o_.quiet)
      std::printf("viscera-replay: published %llu messages in %.1f s\n", static_cast<unsigned long long>(published_),
                  std::chrono::duration<double>(Clock::now() - wall_start).count());
    if (server_joined_) {
      std::fprintf(stderr, "viscera-replay: stopped: %s\n", live_server_.c_str());
      return 3;
    }
    return 0;
  }

 private:
  std::uint64_t at(double s) const { return t0_ + static_cast<std::uint64_t>(std::max(0.0, s) * 1e9); }
  std::uint64_t clamp(std::int64_t t) const {
    return static_cast<std::uint64_t>(std::clamp<std::int64_t>(t, static_cast<std::int64_t>(from_), static_cast<std::int64_t>(to_)));
  }

  void publish_scene() {
    if (!scene_) return;
    proto::Scene s = *scene_;
    s.paused = s.paused || clock_.paused();
    s.recent_requests.insert(s.recent_requests.end(), outcomes_.begin(), outcomes_.end());
    publisher_->publish(proto::Stream::scene_state, 0, proto::encode(s));
  }

  /// What a client joining at recording time `t` must have: the newest sample of each state
  /// stream (scene state, scene files) before it, and the whole surface as it stood then (the
  /// newest surface message may be a patch of the one before: schema 16).
  void prime(std::uint64_t t) {
    std::map<std::pair<proto::Stream, std::uint32_t>, std::vector<std::uint8_t>> last;
    std::map<std::uint32_t, proto::SurfaceAssembler> surfaces;
    std::string why;
    recording_.for_each(
        [&](const rec::RecordedChannel& ch, const mcap::Message& m) {
          if (ch.stream == proto::Stream::surface_topology) {
            if (const auto message = proto::decode_surface_topology(m.data, &why); message && surfaces[ch.source_id].take(*message))
              last[{ch.stream, ch.source_id}] = proto::encode(*surfaces[ch.source_id].surface());
          } else if (proto::stream_info(ch.stream).state) {
            last[{ch.stream, ch.source_id}] = m.data;
          }
          return true;
        },
        t0_, t);
    for (const auto& [key, payload] : last) {
      if (key.first == proto::Stream::scene_state) {
        scene_ = proto::decode_scene(payload, &why);
        publish_scene();
      } else {
        publisher_->publish(key.first, key.second, payload);
      }
    }
  }

  /// Publishes from `cursor` at the clock's pace until the end, a seek, a quit or the stop;
  /// returns the recording time of the last message published.
  std::uint64_t play_until_interrupted(std::uint64_t cursor) {
    recording_.for_each(
        [&](const rec::RecordedChannel& ch, const mcap::Message& m) {
          if (!wait_until_due(m.log_time)) return false;
          if (ch.stream == proto::Stream::scene_state) {
            std::string why;
            if (auto s = proto::decode_scene(m.data, &why)) scene_ = std::move(s);
            publish_scene();
          } else {
            publisher_->publish(ch.stream, ch.source_id, m.data);
          }
          ++published_;
          cursor = m.log_time;
          print_status(cursor);
          return true;
        },
        cursor, to_);
    return cursor;
  }

  /// Handles input until recording time `t` is due; false when playing must stop (seek, quit).
  bool wait_until_due(std::uint64_t t) {
    for (;;) {
      handle_input();
      if (quit_ || seek_to_ || stop_.load()) return false;
      const auto now = Clock::now();
      const auto due = clock_.due(t);
      if (now >= due) return true;
      std::this_thread::sleep_for(std::min<Clock::duration>(due - now, std::chrono::milliseconds(10)));
    }
  }

  void print_status(std::uint64_t cursor) {
    if (o_.quiet || Clock::now() - last_status_ < std::chrono::seconds(1)) return;
    last_status_ = Clock::now();
    std::printf("viscera-replay: %s of %s%s, %llu messages\n", seconds(cursor - t0_).c_str(), seconds(to_ - t0_).c_str(),
                clock_.paused() ? " (paused)" : "", static_cast<unsigned long long>(published_));
    std::fflush(stdout);
  }

  /// Keys and session requests: pause, resume, seek, quit; and a server that joins the partition.
  void handle_input() {
    const auto now = Clock::now();
    if (now - server_checked_ >= std::chrono::milliseconds(100)) {
      server_checked_ = now;
      server_joined_ = publisher_->live_server();
      quit_ = quit_ || server_joined_;
    }
    handle_keys(terminal_->keys(), now);
    bool answered = false;
    requests_->take([&](const client::TapSample& s) {
      std::string why;
      if (const auto r = proto::decode_session_request(s.payload, &why)) {
        outcomes_.push_back(answer(*r, now));
        while (outcomes_.size() > 8) outcomes_.pop_front();
        answered = true;
      }
    });
    if (answered) publish_scene();
  }

  void handle_keys(const std::string& keys, Clock::time_point now) {
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const char k = keys[i];
      if (k == 'q') quit_ = true;
      if (k == ' ') clock_.paused() ? clock_.resume(now) : clock_.pause(now);
      if (k == '\x1b' && i + 2 < keys.size() && keys[i + 1] == '[') {
        const auto pos = static_cast<std::int64_t>(clock_.position(now));
        if (keys[i + 2] == 'C') seek_to_ = clamp(pos + 5'000'000'000);
        if (keys[i + 2] == 'D') seek_to_ = clamp(pos - 5'000'000'000);
        i += 2;
      }
    }
  }

  /// A session request sent to the replayer: pause, resume and seek act on the playback; the
  /// rest are refused with the reason.
  proto::RequestOutcome answer(const proto::SessionRequest& r, Clock::time_point now) {
    proto::RequestOutcome out{r.client_id, r.request_seq, r.action, true, ""};
    switch (r.action) {
      case proto::Action::pause:
        clock_.pause(now);
        out.message = "replay paused at " + seconds(clock_.position(now) - t0_);
        break;
      case proto::Action::resume:
        clock_.resume(now);
        out.message = "replay resumed at " + seconds(clock_.position(now) - t0_);
        break;
      case proto::Action::seek:
        seek_to_ = clamp(static_cast<std::int64_t>(at(r.seek_s)));
        out.message = "replay sought to " + seconds(*seek_to_ - t0_);
        break;
      default:
        out.accepted = false;
        out.message = std::string("a replay cannot ") + proto::action_name(r.action) + " (it plays a recording; control a live server instead)";
    }
    return out;
  }

  const PlayOptions& o_;
  const std::atomic<bool>& stop_;
  rec::Recording recording_;
  std::uint64_t t0_, t_end_, from_, to_;
  std::uint32_t domain_;
  std::string live_server_;  ///< why a replay stops when a server joins its partition
  client::StreamPublisher* publisher_ = nullptr;  // alive during run()
  client::StreamTap* requests_ = nullptr;
  RawTerminal* terminal_ = nullptr;
  std::optional<proto::Scene> scene_;
  std::deque<proto::RequestOutcome> outcomes_;
  rec::PlaybackClock clock_{from_, o_.rate, Clock::now()};
  bool quit_ = false, server_joined_ = false;
  std::optional<std::uint64_t> seek_to_;
  std::uint64_t published_ = 0;
  Clock::time_point server_checked_ = Clock::now(), last_status_ = Clock::now();
};

}  // namespace

int play(const PlayOptions& o, const std::atomic<bool>& stop) { return Player(o, stop).run(); }

}  // namespace viscera::replay
