#include "viscera/client/device_loop.hpp"

#include <cstdio>

namespace viscera::client {

namespace {
template <class... A>
std::string line(const char* format, A... a) {
  char b[320];
  std::snprintf(b, sizeof b, format, a...);
  return b;
}
void add(std::string& note, const std::string& more) { note += note.empty() ? more : "\n" + more; }
}  // namespace

DeviceLoop::DeviceLoop(const DeviceLoopOptions& options, std::uint32_t generation)
    : o_(options), renderer_(options.max_force_n, options.blend_s, options.fade), generation_(generation) {}

bool DeviceLoop::scene_check_due(double t_s) const { return t_s - last_scene_check_ >= 0.1 && server_lost_t_ < 0; }

DeviceLoop::Step DeviceLoop::next(double t, ServerState server, const std::optional<InstrumentView>& scene) {
  Step s;
  if (server == ServerState::lost && server_lost_t_ < 0) {
    server_lost_t_ = t;
    renderer_.server_lost(t);
    add(s.note, line("t = %5.2f s  the server is gone (no DDS liveliness); the force fades to zero over %.2f s", t, o_.fade.fade_s));
  }
  if (lost_) {  // the period after the force reached zero: it was rendered
    s.action = Action::end;
    return s;
  }
  if (server_lost_t_ >= 0 && faded_t_ < 0 && renderer_.gain(t) == 0) {
    faded_t_ = t;
    lost_ = !o_.reconnect;  // this period still renders (zero), then the loop ends
    if (o_.reconnect) add(s.note, line("t = %5.2f s  waiting for a server to come back (--reconnect)", t));
  }
  if (faded_t_ >= 0 && server == ServerState::alive) {  // reconnect: a server is back
    pending_ = Claim::server_back;
    s.action = Action::claim_again;
    return s;
  }
  if (scene && server_lost_t_ < 0) {
    last_scene_check_ = t;
    if (scene->generation == generation_) {
      const bool taken = scene->owner != 0 && scene->owner != o_.client_id;
      // Free, though this client claimed it and drove it: another process under this client id
      // released it (or the server released it for silence). Commands would all be refused.
      if (scene->owner == 0 && !standing_by_ && instrument_lost_t_ < 0) {
        instrument_lost_t_ = t;
        renderer_.server_lost(t);
        add(s.note, line("t = %5.2f s  instrument %u is no longer this client's (the server shows it free: released by another client with "
                         "client id %u?); the force fades to zero over %.2f s",
                         t, o_.instrument, o_.client_id, o_.fade.fade_s));
      }
      if (taken != standing_by_) {
        standing_by_ = taken;
        taken_over_ += taken;
        if (taken) renderer_.server_lost(t);
        add(s.note, line(taken ? "t = %5.2f s  instrument %u taken over by client %u: this device stands by until it is handed back"
                               : "t = %5.2f s  instrument %u handed back (owner client %u): driving it again",
                         t, o_.instrument, scene->owner));
      }
    } else {  // a scene loaded at run time releases every instrument
      generation_ = scene->generation;
      standing_by_ = false;
      pending_ = Claim::scene_loaded;
      s.action = Action::claim_again;
      return s;
    }
  }
  if (instrument_lost_t_ >= 0) {  // nothing is sent; the force fades out, then the run ends
    s.action = Action::render_only;
    if (renderer_.gain(t) == 0) {
      faded_t_ = t;
      s.end_after = true;
    }
    return s;
  }
  if (standing_by_) s.action = Action::render_only;  // nothing sent, the device not read; the force fades out
  return s;
}

std::string DeviceLoop::claimed(double t, bool ok, const std::string& why, const InstrumentView& now) {
  const Claim what = pending_;
  pending_ = Claim::none;
  generation_ = now.generation;
  if (what == Claim::server_back) {
    server_lost_t_ = faded_t_ = -1;
    ++server_returns_;
    return line("t = %5.2f s  a server is back: instrument %u %s", t, o_.instrument, ok ? "claimed again" : ("not claimed: " + why).c_str());
  }
  return line("t = %5.2f s  the server loaded scene %s: instrument %u %s", t, now.scene.c_str(), o_.instrument,
              ok ? "claimed again" : ("could not be claimed again: " + why).c_str());
}

}  // namespace viscera::client
