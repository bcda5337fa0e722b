// haptic-client: a haptic device client of viscera-server. It claims an instrument, samples its
// device at the device rate (a virtual device: a scripted gesture or a trajectory file; real
// devices implement viscera::client::Device), streams the tip to the server, renders the
// server's local force model back to the device, prints force and round-trip latency live and
// writes a JSON report. With --watch-mesh it also receives the organ's surface frames.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/command_line.hpp"
#include "scripted_device.hpp"
#include "trajectory_device.hpp"
#include "viscera/client/client.hpp"
#include "viscera/client/local_force_model.hpp"
#include "viscera/client/tick_phase.hpp"
#include "viscera/protocol/dds.hpp"

namespace {

using viscera::protocol::Vector3;

/// Surface frames as a viewer sees them: how many, how often, how far the surface moved.
struct MeshWatch {
  std::vector<float> rest;
  std::uint32_t mesh_id = 0;  // the surface in use (a scene loaded at run time brings a new one)
  std::size_t frames = 0;
  double first_t = -1, last_t = -1;
  bool record = false;  // keep every frame's sample (for --report)
  nlohmann::json samples = nlohmann::json::array();
  void take(viscera::client::Client& client, double t, const Vector3& tip) {
    const auto s = client.surface();
    if (!s) return;
    if (s->mesh_id != mesh_id) {
      rest = s->rest_positions;
      mesh_id = s->mesh_id;
    }
    const auto frame = client.poll_mesh_frame();
    if (!frame || frame->mesh_id != mesh_id || frame->positions.size() != rest.size()) return;
    ++frames;
    if (first_t < 0) first_t = t;
    last_t = t;
    // The largest surface displacement, and that of the rest vertex nearest the tip's x, y.
    double max_d = 0, best = 1e30, under_tip_dz = 0;
    for (std::size_t v = 0; 3 * v < rest.size(); ++v) {
      double d2 = 0;
      for (std::size_t k = 0; k < 3; ++k) d2 += std::pow(frame->positions[3 * v + k] - rest[3 * v + k], 2);
      max_d = std::max(max_d, std::sqrt(d2));
      const double r2 = std::pow(rest[3 * v] - tip[0], 2) + std::pow(rest[3 * v + 1] - tip[1], 2);
      if (r2 < best && rest[3 * v + 2] > tip[2] - 0.1) {
        best = r2;
        under_tip_dz = frame->positions[3 * v + 2] - rest[3 * v + 2];
      }
    }
    if (record)
      samples.push_back({{"t_s", t}, {"mesh_id", frame->mesh_id}, {"frame", frame->frame}, {"sim_time_s", frame->sim_time_s}, {"max_displacement_m", max_d},
                         {"under_tip_dz_m", under_tip_dz}});
  }
  double rate_hz() const { return frames > 1 && last_t > first_t ? static_cast<double>(frames - 1) / (last_t - first_t) : 0.0; }
};

/// One device period as the report lists it. Kept as plain numbers in a vector reserved before the
/// loop: building a JSON object per period cost the 1 kHz loop about a sixth of its CPU time and
/// grew the client by about 2 MB per second; without --report nothing is kept.
struct ForceSample {
  double t_s, tip_z_m, jaw_rad;
  Vector3 force_n, torque_n_m, rendered_force_n;
  bool in_contact;
  double penetration_m, normal_stiffness_n_per_m, model_age_ms;
  std::uint64_t model_age_commands, command_seq;
};

nlohmann::json to_json(const std::vector<ForceSample>& samples) {
  nlohmann::json out = nlohmann::json::array();
  for (const ForceSample& s : samples)
    out.push_back({{"t_s", s.t_s}, {"tip_z_m", s.tip_z_m}, {"jaw_rad", s.jaw_rad},
                   {"force_n", {s.force_n[0], s.force_n[1], s.force_n[2]}},
                   {"torque_n_m", {s.torque_n_m[0], s.torque_n_m[1], s.torque_n_m[2]}},
                   {"in_contact", s.in_contact}, {"penetration_m", s.penetration_m},
                   {"normal_stiffness_n_per_m", s.normal_stiffness_n_per_m},
                   {"rendered_force_n", {s.rendered_force_n[0], s.rendered_force_n[1], s.rendered_force_n[2]}},
                   {"model_age_commands", s.model_age_commands}, {"model_age_ms", s.model_age_ms},
                   {"command_seq", s.command_seq}});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  viscera::cli::CommandLine cl("haptic-client",
      "A haptic device client: claims an instrument of a running viscera-server and drives it from a virtual device.\n"
      "Script 'press': the probe starts 1 cm above the organ at the centre of its top and moves down until the\n"
      "server reports contact, presses DEPTH further by mid-run and comes back to the contact height by the end.\n"
      "Script 'grasp': the grasper moves down to contact (plus DEPTH), closes its jaws, pulls up PULL, opens.\n"
      "--trajectory FILE.csv plays a recorded or designed trajectory instead (docs/PROTOCOL.md).\n"
      "Prints force and command-to-force round trip live; --report writes every sample as JSON.");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("client-id", "N", "this client's id (non-zero, unique per client)", "1");
  cl.flag("instrument", "ID", "instrument to claim", "1");
  cl.flag("duration", "S", "length of the run [s] (default: 4 for scripts, the trajectory's length for --trajectory)");
  cl.flag("rate", "HZ", "device rate [Hz]", "1000");
  cl.flag("depth", "M", "how far to press beyond the first contact [m]", "0.03");
  cl.flag("script", "NAME", "press (probe) | grasp (grasper: touch the top, close the jaws, pull up PULL, open)", "press");
  cl.flag("pull", "M", "grasp script: how far to pull up after grasping [m]", "0.02");
  cl.flag("trajectory", "FILE.csv", "play this trajectory file (time_s,x_m,y_m,z_m[,jaw_rad][,buttons]) instead of a script");
  cl.flag("frame", "NAME", "trajectory positions: scene (absolute) | organ-top (relative to the organ's top centre)", "scene");
  cl.flag("max-force", "N", "device force limit [N]; rendered forces are clamped to it", "15");
  cl.flag("blend", "S", "blend from one local force model to the next over this time [s]", "0.003");
  cl.flag("tick-phase", "US", "send commands this long after each server tick [us] (at --rate = physics rate; negative: loop free)", "100");
  cl.option_switch("watch-mesh", "receive the organ's surface frames and report their rate and the surface's displacement");
  cl.option_switch("quiet", "no live lines, only the summary");
  cl.flag("report", "FILE.json", "write samples and statistics here");
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto client_id = static_cast<std::uint32_t>(cl.number_in("client-id", 1, 4e9));
    const auto instrument = static_cast<std::uint32_t>(cl.number_in("instrument", 1, 1e6));
    const double rate = cl.number_in("rate", 1, 20000), depth = cl.number_in("depth", 0, 0.2);
    const double max_force = cl.number_in("max-force", 0.1, 1000), pull = cl.number_in("pull", 0, 0.2);
    const std::string script = cl.text("script"), frame = cl.text("frame");
    if (script != "press" && script != "grasp") throw viscera::cli::UsageError("--script: '" + script + "' is not press or grasp");
    if (frame != "scene" && frame != "organ-top") throw viscera::cli::UsageError("--frame: '" + frame + "' is not scene or organ-top");
    std::vector<viscera::haptic::TrajectoryPoint> trajectory;
    if (cl.has("trajectory")) {  // before connecting: a bad file fails at once
      try {
        trajectory = viscera::haptic::read_trajectory(cl.text("trajectory"));
      } catch (const std::runtime_error& e) {
        throw viscera::cli::UsageError(e.what());
      }
    }
    const double duration = cl.has("duration") ? cl.number_in("duration", 0.1, 36000) : trajectory.empty() ? 4.0 : trajectory.back().t_s;
    const bool quiet = cl.has("quiet"), watch_mesh = cl.has("watch-mesh");
    const double tick_phase_us = cl.number_in("tick-phase", -1, 1e6);

    viscera::client::Client client(static_cast<std::uint32_t>(cl.number_in("domain", 0, 230)), client_id);
    const auto scene = client.wait_for_scene(std::chrono::seconds(10));
    if (!scene) {
      std::fprintf(stderr, "haptic-client: no viscera-server found in 10 s (same domain and CYCLONEDDS_URI?)\n");
      return 3;
    }
    if (!client.claim(instrument, std::chrono::seconds(5))) {
      std::fprintf(stderr, "haptic-client: instrument %u could not be claimed (taken, or not in scene %s)\n", instrument, scene->name.c_str());
      return 3;
    }
    std::unique_ptr<viscera::client::Device> device;
    if (!trajectory.empty()) {
      const Vector3 origin = frame == "scene" ? Vector3{0, 0, 0}
                                              : Vector3{0.5 * (scene->bounds_min[0] + scene->bounds_max[0]),
                                                        0.5 * (scene->bounds_min[1] + scene->bounds_max[1]), scene->bounds_max[2]};
      device = std::make_unique<viscera::haptic::TrajectoryDevice>(cl.text("trajectory"), std::move(trajectory), origin);
    } else {
      device = std::make_unique<viscera::haptic::ScriptedDevice>(script, *scene, duration, depth, pull);
    }
    std::printf("haptic-client: scene %s, instrument %u claimed; device: %s, %.0f Hz for %.1f s\n", scene->name.c_str(), instrument,
                device->name().c_str(), rate, duration);
    std::fflush(stdout);

    // Tip of each of the last 4096 commands, for the local model (a ring: no allocation per period).
    struct Sent {
      std::uint64_t seq = 0;
      Vector3 tip{};
    };
    std::vector<Sent> sent(4096);
    std::uint64_t seq = 0, clamps = 0, model_seq = 0;
    viscera::client::LocalForceRenderer renderer(max_force, cl.number_in("blend", 0, 0.1));
    MeshWatch mesh;
    const bool record = cl.has("report");
    mesh.record = record;
    std::vector<ForceSample> samples;
    // Reserved up front so the loop never reallocates (pages are touched only as samples come).
    if (record) samples.reserve(static_cast<std::size_t>(std::min(duration * rate + 16, double{1 << 22})));
    const auto period = std::chrono::nanoseconds(static_cast<long long>(1e9 / rate));
    const auto start = std::chrono::steady_clock::now();
    const double start_epoch_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    auto next = start;
    // Commands timed to arrive just after a physics tick, in the server's idle time (tick_phase.hpp).
    std::optional<viscera::client::TickPhase> phase;
    if (tick_phase_us >= 0) phase.emplace(period, std::chrono::nanoseconds(std::llround(tick_phase_us * 1e3)));
    const auto rate_matches = [&](const viscera::protocol::Scene& s) { return std::abs(s.physics_rate_hz - rate) <= 0.01 * rate; };
    bool in_phase_possible = rate_matches(*scene);
    std::uint64_t phased = 0, near_phase = 0;  // periods timed by the lock; of them within 50 us of the target
    double last_print = -1, last_scene_check = 0;
    std::uint32_t generation = scene->generation;
    for (;;) {
      const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (t >= duration) break;
      if (t - last_scene_check >= 0.1) {  // a scene loaded at run time releases every instrument: claim it again
        last_scene_check = t;
        const auto now = client.scene();
        if (now) in_phase_possible = rate_matches(*now);  // the physics rate may change at run time
        if (now && now->generation != generation) {
          generation = now->generation;
          const bool again = client.claim(instrument, std::chrono::seconds(2));
          std::printf("t = %5.2f s  the server loaded scene %s: instrument %u %s\n", t, now->name.c_str(), instrument,
                      again ? "claimed again" : "could not be claimed again");
          std::fflush(stdout);
          next = std::chrono::steady_clock::now();
          continue;
        }
      }
      const auto in = device->read(t);
      if (in.finished) break;
      client.send_tip(instrument, in.tip_m, in.jaw_rad);
      ++seq;
      sent[seq % sent.size()] = {seq, in.tip_m};
      // Wait for the answer to this command until shortly before the next device period.
      if (const auto f = client.wait_force(instrument, next + period - std::chrono::microseconds(100))) {
        // The force rendered now, from the server's local models at the current tip: a new model
        // (the answer to a newer command) is blended in over --blend seconds.
        if (f->command_seq > model_seq)
          if (const Sent& it = sent[f->command_seq % sent.size()]; it.seq == f->command_seq && it.seq != 0) {
            renderer.update(*f, it.tip, t);
            model_seq = f->command_seq;
          }
        const auto rendered = renderer.render(in.tip_m, t);
        device->render(rendered.force, f->in_contact);
        clamps += rendered.clamped;
        double normal_stiffness = 0;  // n^T K n of the local model [N/m]
        for (std::size_t i = 0; i < 3; ++i)
          for (std::size_t j = 0; j < 3; ++j) normal_stiffness += f->contact_normal[i] * f->stiffness[3 * i + j] * f->contact_normal[j];
        if (record)
          samples.push_back({t, in.tip_m[2], in.jaw_rad, f->force, f->torque, rendered.force, f->in_contact, f->penetration_m,
                             normal_stiffness, 1e3 * renderer.model_age_s(t), seq - f->command_seq, f->command_seq});
        if (!quiet && t - last_print >= 0.25) {
          const auto rtt = client.round_trip();
          std::printf("t = %5.2f s  tip z %.4f m  force (%6.3f, %6.3f, %6.3f) N%s  round trip p50 %.0f us p99 %.0f us%s\n", t,
                      in.tip_m[2], f->force[0], f->force[1], f->force[2], f->in_contact ? "  contact" : "         ", rtt.p50_us,
                      rtt.p99_us, watch_mesh ? ("  mesh frames " + std::to_string(mesh.frames)).c_str() : "");
          last_print = t;
          std::fflush(stdout);
        }
      }
      if (watch_mesh) mesh.take(client, t, in.tip_m);
      next += period;
      if (phase && in_phase_possible)
        if (const auto tick_end = client.last_tick_end_ns(instrument)) {
          const std::int64_t next_ns = viscera::protocol::now_ns() +
                                       std::chrono::duration_cast<std::chrono::nanoseconds>(next - std::chrono::steady_clock::now()).count();
          ++phased;
          near_phase += std::abs(phase->error(next_ns, *tick_end).count()) < 50'000;
          next += phase->correction(next_ns, *tick_end);
        }
      std::this_thread::sleep_until(next);
    }
    client.release(instrument);
    const auto rtt = client.round_trip();
    std::printf("haptic-client: %zu round trips: p50 %.0f us, p99 %.0f us, max %.0f us; %llu payloads rejected; %llu rendered forces clamped to %.1f N\n",
                rtt.samples, rtt.p50_us, rtt.p99_us, rtt.max_us, static_cast<unsigned long long>(client.rejected()),
                static_cast<unsigned long long>(clamps), max_force);
    if (watch_mesh)
      std::printf("haptic-client: %zu surface frames at %.1f Hz\n", mesh.frames, mesh.rate_hz());
    if (phased > 0)
      std::printf("haptic-client: commands timed %.0f us after the server's ticks in %llu periods, %.1f%% of them within 50 us\n",
                  tick_phase_us, static_cast<unsigned long long>(phased), 100.0 * static_cast<double>(near_phase) / static_cast<double>(phased));
    if (cl.has("report")) {
      nlohmann::json r{{"scene", scene->name}, {"instrument", instrument}, {"client_id", client_id}, {"rate_hz", rate},
                       {"start_epoch_s", start_epoch_s},
                       {"duration_s", duration}, {"device", device->name()},
                       {"round_trip_us", {{"samples", rtt.samples}, {"p50", rtt.p50_us}, {"p99", rtt.p99_us}, {"max", rtt.max_us}}},
                       {"tick_phase", {{"offset_us", tick_phase_us}, {"periods", phased}, {"within_50us", near_phase}}},
                       {"samples", to_json(samples)}};
      if (watch_mesh) r["mesh"] = {{"frames", mesh.frames}, {"rate_hz", mesh.rate_hz()}, {"samples", mesh.samples}};
      std::ofstream(cl.text("report")) << r.dump(1) << "\n";
    }
    return 0;
  } catch (const viscera::cli::UsageError& e) {
    std::fprintf(stderr, "haptic-client: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haptic-client: %s\n", e.what());
    return 1;
  }
}
