#include "viscera/client/device_runner.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>
#include <vector>

#include "viscera/client/force_slew_limit.hpp"
#include "viscera/client/tick_phase.hpp"

namespace viscera::client {

namespace {
std::optional<InstrumentView> view(const std::optional<protocol::Scene>& s, std::uint32_t instrument) {
  if (!s) return std::nullopt;
  InstrumentView v{s->generation, 0, s->name};
  for (const auto& i : s->instruments)
    if (i.instrument_id == instrument) v.owner = i.owner_client_id;
  return v;
}
}  // namespace

DeviceRunResult run_device(Client& client, Device& device, const DeviceRunOptions& o, std::uint32_t generation, const DeviceRunHooks& hooks) {
  using clock = std::chrono::steady_clock;
  DeviceLoop loop(o.loop, generation);
  DeviceRunResult run;
  const auto note = [&](const std::string& s) {
    if (!s.empty() && hooks.note) hooks.note(s);
  };
  // Tip of each of the last 4096 commands, for the local model (a ring: no allocation per period).
  struct Sent {
    std::uint64_t seq = 0;
    protocol::Vector3 tip{};
  };
  std::vector<Sent> sent(4096);
  std::uint64_t seq = 0, model_seq = 0;
  const auto period = std::chrono::nanoseconds(static_cast<long long>(1e9 / o.rate_hz));
  const auto start = clock::now();
  auto next = start;
  // Commands timed to arrive just after a physics tick, in the server's idle time (tick_phase.hpp).
  std::optional<TickPhase> phase;
  if (o.tick_phase_us >= 0) phase.emplace(period, std::chrono::nanoseconds(std::llround(o.tick_phase_us * 1e3)));
  const auto rate_matches = [&](const protocol::Scene& s) { return std::abs(s.physics_rate_hz - o.rate_hz) <= 0.01 * o.rate_hz; };
  bool in_phase_possible = true;
  protocol::Vector3 last_tip{};
  double last_model_t = -1;  // when the newest model came, while driving (-1: not driving)
  // Every force the device is told to render passes the slew limit (force_slew_limit.hpp).
  ForceSlewLimit slew(o.loop.slew_n_per_ms * 1e3, 1.0 / o.rate_hz);
  loop.renderer().restart_at_next_model();  // the instrument was just claimed: the tool may be anywhere in the tissue
  const auto render_only = [&](double t) { device.render(slew.limit(loop.renderer().render(last_tip, t).force, t), false); };
  for (;;) {
    const double t = std::chrono::duration<double>(clock::now() - start).count();
    if (t >= o.duration_s) break;
    std::optional<InstrumentView> scene;
    if (loop.scene_check_due(t)) {
      const auto now = client.scene();
      if (now) in_phase_possible = rate_matches(*now);  // the physics rate may change at run time
      scene = view(now, o.loop.instrument);
    }
    const DeviceLoop::Step step = loop.next(t, client.server_state(), scene);
    note(step.note);
    if (step.action == DeviceLoop::Action::render_only) last_model_t = -1;  // nothing sent: no answer is awaited
    if (step.action == DeviceLoop::Action::end) break;
    if (step.action == DeviceLoop::Action::claim_again) {
      const auto again = client.claim(o.loop.instrument, std::chrono::seconds(5));
      const auto now = view(client.scene(), o.loop.instrument);
      note(loop.claimed(t, static_cast<bool>(again), again.why, now.value_or(InstrumentView{})));
      next = clock::now();
      continue;
    }
    if (step.action == DeviceLoop::Action::render_only) {
      render_only(t);
      if (step.end_after) break;
      next += period;
      std::this_thread::sleep_until(next);
      continue;
    }
    const DeviceSample in = device.read(t);
    if (in.finished) break;
    last_tip = in.tip_m;
    client.send_tip(o.loop.instrument, in.tip_m, in.jaw_rad, in.buttons);
    ++seq;
    sent[seq % sent.size()] = {seq, in.tip_m};
    // Wait for the answer to this command until shortly before the next device period.
    if (const auto f = client.wait_force(o.loop.instrument, next + period - std::chrono::microseconds(100))) {
      // The force rendered now, from the server's local models at the current tip: a new model
      // (the answer to a newer command) is blended in over the blend time.
      if (f->command_seq > model_seq)
        if (const Sent& it = sent[f->command_seq % sent.size()]; it.seq == f->command_seq && it.seq != 0) {
          loop.renderer().update(*f, it.tip, t);
          note(loop.organ_epoch(t, f->organ_epoch));
          model_seq = f->command_seq;
          if (last_model_t >= 0 && t - last_model_t > run.longest_silence_s) {
            run.longest_silence_s = t - last_model_t;
            run.longest_silence_end_t_s = t;
          }
          last_model_t = t;
        }
      auto rendered = loop.renderer().render(in.tip_m, t);
      rendered.force = slew.limit(rendered.force, t);
      device.render(rendered.force, f->in_contact);
      device.model_age(loop.renderer().model_age_s(t));
      run.clamps += rendered.clamped;
      if (hooks.period) hooks.period({t, in, *f, rendered, loop.renderer().model_age_s(t), seq - f->command_seq});
    }
    next += period;
    if (phase && in_phase_possible)
      if (const auto tick_end = client.last_tick_end_ns(o.loop.instrument)) {
        const std::int64_t next_ns = now_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(next - clock::now()).count();
        ++run.phased;
        run.near_phase += std::abs(phase->error(next_ns, *tick_end).count()) < 50'000;
        next += phase->correction(next_ns, *tick_end);
      }
    std::this_thread::sleep_until(next);
  }
  run.server_lost_t_s = loop.server_lost_t_s();
  run.faded_t_s = loop.faded_t_s();
  run.instrument_lost_t_s = loop.instrument_lost_t_s();
  run.server_returns = loop.server_returns();
  run.taken_over = loop.taken_over();
  run.instrument_losses = loop.instrument_losses();
  run.stall_s = loop.stall_s();
  run.stall_end_t_s = loop.stall_end_t_s();
  run.lost = loop.lost();
  run.slew_limited = slew.limited();
  run.largest_step_asked_n = slew.largest_step_asked_n();
  return run;
}

}  // namespace viscera::client
