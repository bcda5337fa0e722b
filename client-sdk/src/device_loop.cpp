#include "viscera/client/device_loop.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "viscera/protocol/dds.hpp"

namespace viscera::client {

namespace {
template <class... A>
std::string line(const char* format, A... a) {
  char b[320];
  std::snprintf(b, sizeof b, format, a...);
  return b;
}
void add(std::string& note, const std::string& more) { note += note.empty() ? more : "\n" + more; }
// [s] the liveliness lease, which is also the server's lease on a silent owner's instrument
const double kLeaseS = std::chrono::duration<double>(viscera::protocol::kLivelinessLease).count();
}  // namespace

DeviceLoop::DeviceLoop(const DeviceLoopOptions& options, std::uint32_t generation)
    : o_(options), renderer_(options.max_force_n, options.blend_s, options.fade), generation_(generation) {}

bool DeviceLoop::scene_check_due(double t_s) const { return t_s - last_scene_check_ >= 0.1 && server_lost_t_ < 0; }

DeviceLoop::Step DeviceLoop::next(double t, ServerState server, const std::optional<InstrumentView>& scene) {
  Step s;
  // A gap between two periods longer than the lease: this process did not run (stopped, starved,
  // swapped out). The server heard nothing from it meanwhile and may have freed its instrument; and
  // this process's DDS may call the server gone until it hears from it again.
  if (last_t_ >= 0 && t - last_t_ > kLeaseS) {
    stall_s_ = std::max(stall_s_, t - last_t_);
    stall_end_t_ = t;
    add(s.note, line("t = %5.2f s  this process did not run for %.2f s, longer than the server's %.1f s lease", t, t - last_t_, kLeaseS));
  }
  last_t_ = t;
  if (server == ServerState::lost && server_lost_t_ < 0) {
    server_lost_t_ = t;
    renderer_.server_lost(t);
    const bool after_stall = stall_end_t_ >= 0 && t - stall_end_t_ < kLeaseS;
    add(s.note, line("t = %5.2f s  the server is gone (no DDS liveliness%s); the force fades to zero over %.2f s", t,
                     after_stall ? ", just after this process's own stall: it may be there still" : "", o_.fade.fade_s));
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
      if (taken != standing_by_) {
        standing_by_ = taken;
        if (taken) renderer_.server_lost(t);
        if (taken && instrument_lost_t_ >= 0)  // it was free, and another client claimed it
          add(s.note,
              line("t = %5.2f s  instrument %u is held by client %u now: this device waits until it is free", t, o_.instrument, scene->owner));
        else if (taken)
          add(s.note, line("t = %5.2f s  instrument %u taken over by client %u: this device stands by until it is handed back", t, o_.instrument,
                           scene->owner));
        else if (scene->owner == o_.client_id)
          add(s.note, line("t = %5.2f s  instrument %u handed back (owner client %u): driving it again", t, o_.instrument, scene->owner));
        taken_over_ += taken && instrument_lost_t_ < 0;
      }
      // Free, though this client held it: the server heard nothing from it for longer than its
      // lease (a stall of this process), or whoever held it released it (the console that had
      // taken it over, another process under this client id). Commands would all be refused.
      if (scene->owner == 0 && instrument_lost_t_ < 0) {
        instrument_lost_t_ = t;
        ++instrument_losses_;
        renderer_.server_lost(t);
        add(s.note, line("t = %5.2f s  instrument %u is no longer this client's: the server shows it free (it frees an instrument whose "
                         "owner it has not heard from for its %.1f s lease, or whoever held it released it); the force fades to zero "
                         "over %.2f s%s",
                         t, o_.instrument, kLeaseS, o_.fade.fade_s, o_.reconnect ? ", then it is claimed again (--reconnect)" : ""));
      }
    } else {  // a scene loaded at run time releases every instrument
      generation_ = scene->generation;
      standing_by_ = false;
      pending_ = Claim::scene_loaded;
      s.action = Action::claim_again;
      return s;
    }
  }
  if (instrument_lost_t_ >= 0) {  // nothing is sent; the force fades out, then the run ends (or, reconnecting, claims again)
    s.action = Action::render_only;
    if (renderer_.gain(t) > 0) return s;
    if (!o_.reconnect) {
      faded_t_ = t;
      s.end_after = true;
    } else if (t >= retry_t_ && !standing_by_) {  // not while another client holds it
      pending_ = Claim::instrument_free;
      s.action = Action::claim_again;
    }
    return s;
  }
  if (standing_by_) s.action = Action::render_only;  // nothing sent, the device not read; the force fades out
  return s;
}

std::string DeviceLoop::claimed(double t, bool ok, const std::string& why, const InstrumentView& now) {
  last_t_ = -1;  // the claim took its time: not a stall
  const Claim what = pending_;
  pending_ = Claim::none;
  generation_ = now.generation;
  if (ok) {
    instrument_lost_t_ = -1;  // whatever the claim was for, the instrument is this client's again
    // The tool may be anywhere in the tissue: the force ramps from what the hand felt to the first
    // answer's (which may come 0.1 s after the claim).
    renderer_.restart_at_next_model();
    epoch_.reset();  // the new organ's epoch, in the next force, is no jump: the claim faded in already
  }
  if (what == Claim::instrument_free) {
    retry_t_ = ok ? 0 : t + kRetryS;
    return line("t = %5.2f s  instrument %u %s", t, o_.instrument,
                ok ? "claimed again" : ("not claimed again: " + why + line("; trying again in %.0f s", kRetryS)).c_str());
  }
  if (what == Claim::server_back) {
    server_lost_t_ = faded_t_ = -1;
    ++server_returns_;
    return line("t = %5.2f s  a server is back: instrument %u %s", t, o_.instrument, ok ? "claimed again" : ("not claimed: " + why).c_str());
  }
  return line("t = %5.2f s  the server loaded scene %s: instrument %u %s", t, now.scene.c_str(), o_.instrument,
              ok ? "claimed again" : ("could not be claimed again: " + why).c_str());
}

std::string DeviceLoop::organ_epoch(double t, std::uint32_t epoch) {
  const bool jumped = epoch_ && *epoch_ != epoch;
  epoch_ = epoch;
  if (!jumped) return {};
  renderer_.restart(t);
  return line("t = %5.2f s  the organ was reset, reloaded, paused, resumed or given another material: the force ramps to the new one over %.2f s", t,
              o_.fade.fade_in_s);
}

}  // namespace viscera::client
