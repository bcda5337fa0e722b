// haptic-client: a haptic device client of viscera-server. It claims an instrument, samples its  // SPDX-License-Identifier: Apache-2.0
// device at the device rate (a virtual device: a scripted gesture or a trajectory file; real
// devices implement viscera::client::Device), streams the tip to the server, renders the
// server's local force model back to the device, prints force and round-trip latency live and
// writes a JSON report. With --watch-mesh it also receives the organ's surface frames. When the
// server goes away (stopped, killed, its host cut off) the rendered force fades to zero, the client
// says so and exits with status 4, or with --reconnect waits for a server to come back.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "viscera/client/client.hpp"
#include "viscera/client/device_runner.hpp"
#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/protocol/dds.hpp"

#include "palpating_device.hpp"
#include "say.hpp"
#include "scripted_device.hpp"
#include "trajectory_device.hpp"

namespace {

using viscera::haptic::say;
using viscera::protocol::Vector3;

/// Surface frames as a viewer sees them: how many, how often, how far the surface moved.
struct MeshWatch {
  std::vector<float> rest;
  std::uint32_t mesh_id = 0;  // the surface in use (a scene loaded at run time brings a new one)
  std::uint32_t generation = 0;  // its topology generation (a cut brings a new one)
  std::size_t frames = 0;
  double first_t = -1, last_t = -1;
  bool record = false;  // keep every frame's sample (for --report)
  nlohmann::json samples = nlohmann::json::array();
  void take(viscera::client::Client& client, double t, const Vector3& tip) {
    const auto s = client.surface();
    if (!s) return;
    if (s->mesh_id != mesh_id || s->topology_generation != generation) {
      rest = s->rest_positions;
      mesh_id = s->mesh_id;
      generation = s->topology_generation;
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
      samples.push_back({{"t_s", t},
                         {"mesh_id", frame->mesh_id},
                         {"frame", frame->frame},
                         {"sim_time_s", frame->sim_time_s},
                         {"max_displacement_m", max_d},
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
    out.push_back({{"t_s", s.t_s},
                   {"tip_z_m", s.tip_z_m},
                   {"jaw_rad", s.jaw_rad},
                   {"force_n", {s.force_n[0], s.force_n[1], s.force_n[2]}},
                   {"torque_n_m", {s.torque_n_m[0], s.torque_n_m[1], s.torque_n_m[2]}},
                   {"in_contact", s.in_contact},
                   {"penetration_m", s.penetration_m},
                   {"normal_stiffness_n_per_m", s.normal_stiffness_n_per_m},
                   {"rendered_force_n", {s.rendered_force_n[0], s.rendered_force_n[1], s.rendered_force_n[2]}},
                   {"model_age_commands", s.model_age_commands},
                   {"model_age_ms", s.model_age_ms},
                   {"command_seq", s.command_seq}});
  return out;
}

struct Options {
  std::uint32_t domain = 0, client_id = 1, instrument = 1;
  double rate_hz = 1000, depth_m = 0.03, pull_m = 0.02, length_m = 0.04, offset_y_m = 0, hold_s = -1, force_n = 1.0, max_force_n = 15,
         blend_s = 0.003, tick_phase_us = 100, duration_s = 4, slew_n_per_ms = 1.0;
  viscera::client::FadePolicy fade;
  std::string station, script, frame, report;
  std::vector<viscera::haptic::TrajectoryPoint> trajectory;
  std::string trajectory_file;
  bool quiet = false, watch_mesh = false, reconnect = false;
};

Options parse(viscera::common::CommandLine& cl) {
  Options o;
  o.domain = static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230));
  o.station = viscera::protocol::checked_station(cl.text("station"));
  o.client_id = static_cast<std::uint32_t>(cl.integer_in("client-id", 1, 4000000000));
  o.instrument = static_cast<std::uint32_t>(cl.integer_in("instrument", 1, 1000000));
  o.rate_hz = cl.number_in("rate", 1, 20000);
  o.depth_m = cl.number_in("depth", 0, 0.2);
  o.max_force_n = cl.number_in("max-force", 0.1, 1000);
  o.pull_m = cl.number_in("pull", 0, 0.2);
  o.length_m = cl.number_in("length", 0.001, 0.3);
  o.offset_y_m = cl.number_in("offset-y", -0.3, 0.3);
  if (cl.has("hold")) o.hold_s = cl.number_in("hold", 0, 3600);
  o.force_n = cl.number_in("force", 0.01, 50);
  o.blend_s = cl.number_in("blend", 0, 0.1);
  o.fade.fade_s = cl.number_in("fade", 0.001, 5);
  o.fade.stale_after_s = cl.number_in("stale-after", 0.001, 5);
  o.fade.fade_in_s = cl.number_in("fade-in", 0.001, 5);
  o.slew_n_per_ms = cl.number_in("slew-limit", 0.01, 1000);
  o.script = cl.text("script");
  o.frame = cl.text("frame");
  if (o.script != "press" && o.script != "grasp" && o.script != "hold" && o.script != "palpate" && o.script != "incise")
    throw viscera::common::UsageError("--script: '" + o.script + "' is not press, grasp, hold, palpate or incise");
  if (o.frame != "scene" && o.frame != "organ-top") throw viscera::common::UsageError("--frame: '" + o.frame + "' is not scene or organ-top");
  if (cl.has("trajectory")) {  // before connecting: a bad file fails at once
    o.trajectory_file = cl.text("trajectory");
    try {
      o.trajectory = viscera::haptic::read_trajectory(o.trajectory_file);
    } catch (const std::runtime_error& e) {
      throw viscera::common::UsageError(e.what());
    }
  }
  o.duration_s = cl.has("duration") ? cl.number_in("duration", 0.1, 36000) : o.trajectory.empty() ? 4.0 : o.trajectory.back().t_s;
  o.quiet = cl.has("quiet");
  o.watch_mesh = cl.has("watch-mesh");
  o.reconnect = cl.has("reconnect");
  o.tick_phase_us = cl.number_in("tick-phase", -1, 1e6);
  if (cl.has("report")) o.report = cl.text("report");
  if (!o.report.empty() && !o.trajectory_file.empty()) viscera::common::refuse_overwrite(o.report, {o.trajectory_file}, "--report");
  if (!o.report.empty()) viscera::common::refuse_existing_output(o.report, cl.has("replace"), "--report");
  return o;
}

std::unique_ptr<viscera::client::Device> make_device(const Options& o, const viscera::protocol::Scene& scene) {
  if (o.trajectory.empty() && o.script == "palpate") return std::make_unique<viscera::haptic::PalpatingDevice>(scene, o.depth_m, !o.quiet);
  if (o.trajectory.empty())
    return std::make_unique<viscera::haptic::ScriptedDevice>(o.script, scene, o.duration_s, o.depth_m, o.pull_m, o.hold_s, o.force_n, o.length_m,
                                                             o.offset_y_m);
  const Vector3 origin = o.frame == "scene" ? Vector3{0, 0, 0}
                                            : Vector3{0.5 * (scene.bounds_min[0] + scene.bounds_max[0]),
                                                      0.5 * (scene.bounds_min[1] + scene.bounds_max[1]), scene.bounds_max[2]};
  return std::make_unique<viscera::haptic::TrajectoryDevice>(o.trajectory_file, o.trajectory, origin);
}

/// What the run saw, for the summary and the report: the SDK loop's result, and what this
/// program keeps besides (every period's numbers for --report, the surface frames).
struct RunResult : viscera::client::DeviceRunResult {
  std::vector<ForceSample> samples;
  MeshWatch mesh;
};

void print_live(const Options& o, viscera::client::Client& client, double t, const Vector3& tip, const viscera::protocol::Force& f,
                std::size_t frames) {
  const auto rtt = client.round_trip();
  say("t = %5.2f s  tip z %.4f m  force (%6.3f, %6.3f, %6.3f) N%s  round trip p50 %.0f us p99 %.0f us%s", t, tip[2], f.force[0], f.force[1],
      f.force[2], f.in_contact ? "  contact" : "         ", rtt.p50_us, rtt.p99_us,
      o.watch_mesh ? ("  mesh frames " + std::to_string(frames)).c_str() : "");
}

/// The SDK's device loop (device_runner.hpp), with this program's live lines, report samples and
/// surface frames as its hooks.
RunResult run_device(const Options& o, viscera::client::Client& client, viscera::client::Device& device, std::uint32_t generation) {
  RunResult run;
  run.mesh.record = !o.report.empty();
  // Reserved up front so the loop never reallocates (pages are touched only as samples come).
  if (!o.report.empty()) run.samples.reserve(static_cast<std::size_t>(std::min(o.duration_s * o.rate_hz + 16, double{1 << 22})));
  viscera::client::DeviceRunOptions options;
  options.loop = {o.client_id, o.instrument, o.max_force_n, o.blend_s, o.fade, o.reconnect, o.slew_n_per_ms};
  options.rate_hz = o.rate_hz;
  options.duration_s = o.duration_s;
  options.tick_phase_us = o.tick_phase_us;
  double last_print = -1;
  viscera::client::DeviceRunHooks hooks;
  hooks.note = [](const std::string& line) { say("%s", line.c_str()); };
  hooks.period = [&](const viscera::client::DevicePeriod& p) {
    const auto& f = p.force;
    if (!o.report.empty()) {
      double normal_stiffness = 0;  // n^T K n of the local model [N/m]
      for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) normal_stiffness += f.contact_normal[i] * f.stiffness[3 * i + j] * f.contact_normal[j];
      run.samples.push_back({p.t_s, p.device.tip_m[2], p.device.jaw_rad, f.force, f.torque, p.rendered.force, f.in_contact, f.penetration_m,
                             normal_stiffness, 1e3 * p.model_age_s, p.model_age_commands, f.command_seq});
    }
    if (!o.quiet && p.t_s - last_print >= 0.25) {
      print_live(o, client, p.t_s, p.device.tip_m, f, run.mesh.frames);
      last_print = p.t_s;
    }
    if (o.watch_mesh) run.mesh.take(client, p.t_s, p.device.tip_m);
  };
  static_cast<viscera::client::DeviceRunResult&>(run) = viscera::client::run_device(client, device, options, generation, hooks);
  return run;
}

void write_report(const Options& o, const std::string& scene, const std::string& device, double start_epoch_s,
                  const viscera::client::LatencyStats& rtt, const RunResult& run) {
  nlohmann::json r{
      {"scene", scene},
      {"instrument", o.instrument},
      {"client_id", o.client_id},
      {"rate_hz", o.rate_hz},
      {"start_epoch_s", start_epoch_s},
      {"duration_s", o.duration_s},
      {"device", device},
      {"round_trip_us", {{"samples", rtt.samples}, {"p50", rtt.p50_us}, {"p99", rtt.p99_us}, {"max", rtt.max_us}}},
      {"tick_phase", {{"offset_us", o.tick_phase_us}, {"periods", run.phased}, {"within_50us", run.near_phase}}},
      {"fade", {{"stale_after_s", o.fade.stale_after_s}, {"fade_s", o.fade.fade_s}, {"fade_in_s", o.fade.fade_in_s}}},
      {"slew_limit", {{"n_per_ms", o.slew_n_per_ms}, {"periods_limited", run.slew_limited}, {"largest_step_asked_n", run.largest_step_asked_n}}},
      {"server_lost_t_s", run.server_lost_t_s},
      {"taken_over", run.taken_over},
      {"instrument_lost_t_s", run.instrument_lost_t_s},
      {"instrument_losses", run.instrument_losses},
      {"stall_s", run.stall_s},
      {"stall_end_t_s", run.stall_end_t_s},
      {"faded_t_s", run.faded_t_s},
      {"server_returns", run.server_returns},
      {"longest_silence_s", run.longest_silence_s},
      {"longest_silence_end_t_s", run.longest_silence_end_t_s},
      {"samples", to_json(run.samples)}};
  if (o.watch_mesh)
    r["mesh"] = {{"frames", run.mesh.frames},
                 {"rate_hz", run.mesh.rate_hz()},
                 {"topology_generation", run.mesh.generation},
                 {"surface_vertices", run.mesh.rest.size() / 3},
                 {"samples", run.mesh.samples}};
  viscera::common::write_file_text(o.report, r.dump(1) + "\n");
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl(
      "haptic-client",
      "A haptic device client: claims an instrument of a running viscera-server and drives it from a virtual device.\n"
      "Script 'press': the probe starts 1 cm above the organ at the centre of its top and moves down until the\n"
      "server reports contact, presses DEPTH further by mid-run and comes back to the contact height by the end.\n"
      "Script 'grasp': the grasper moves down to contact (plus DEPTH), closes its jaws, pulls up PULL, opens\n"
      "(with --hold: pulls up at 1 cm/s, holds HOLD seconds, then opens).\n"
      "Script 'hold': the probe presses until the force it feels is FORCE and holds it there (a force drill).\n"
      "Script 'incise': the scalpel (instrument 4 of the bundled liver scenes) moves down to contact LENGTH/2 before the top\n"
      "centre, holds its cut button, sinks DEPTH into the tissue, draws the blade LENGTH along +x and rises out (docs/CUTTING.md).\n"
      "Script 'palpate': the probe palpates the organ's top on a grid, pressing DEPTH beyond contact and judging each point\n"
      "by the force held still half way (deeper, a thin lobe bends away), and marks the centre of the stiff area\n"
      "around the stiffest place with button 1 (a palpation exercise; it never reads where the nodule is).\n"
      "--trajectory FILE.csv plays a recorded or designed trajectory instead (docs/PROTOCOL.md).\n"
      "Prints force and command-to-force round trip live; --report writes every sample as JSON.\n"
      "If the server goes away the rendered force fades to zero (--fade) and the client exits with status 4\n"
      "(--reconnect: it waits for a server to come back and claims the instrument again).\n"
      "If the server shows the instrument free though this client held it (the server heard nothing from it for longer\n"
      "than its 0.5 s lease, as in a stall of this process, or another process under this client id released it), the\n"
      "force fades out and the client exits with status 5 (--reconnect: it claims the instrument again, every 1 s until it holds).\n"
      "While another client (an instructor's console) has taken the instrument over, the client sends nothing,\n"
      "its rendered force fades out and the device waits; it drives again once the instrument is handed back.\n"
      "Exit status: 0 done, 2 bad arguments, 3 no server or instrument not claimed, 4 the server went away, 5 the instrument was\n"
      "freed under this client (above), 1 other errors.");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("station", "NAME", "the trainee station whose server to use: its DDS partition (viscera-server --station)", "");
  cl.flag("client-id", "N", "this client's id (non-zero, unique per client)", "1");
  cl.flag("instrument", "ID", "instrument to claim", "1");
  cl.flag("duration", "S", "length of the run [s] (default: 4 for scripts, the trajectory's length for --trajectory)");
  cl.flag("rate", "HZ", "device rate [Hz]", "1000");
  cl.flag("depth", "M", "how far to press beyond the first contact [m]", "0.03");
  cl.flag("script", "NAME", "press | grasp | hold | palpate | incise (above)", "press");
  cl.flag("length", "M", "incise script: the incision's length along x [m]", "0.04");
  cl.flag("offset-y", "M", "incise script: the incision's offset from the top centre along y [m]", "0");
  cl.flag("pull", "M", "grasp script: how far to pull up after grasping [m]", "0.02");
  cl.flag("hold", "S", "grasp script: hold the pull this long, then open [s] (default: open at 75% of the run)");
  cl.flag("force", "N", "hold script: the force to hold [N]", "1.0");
  cl.flag("trajectory", "FILE.csv", "play this trajectory file (time_s,x_m,y_m,z_m[,jaw_rad][,buttons]) instead of a script");
  cl.flag("frame", "NAME", "trajectory positions: scene (absolute) | organ-top (relative to the organ's top centre)", "scene");
  cl.flag("max-force", "N", "device force limit [N]; rendered forces are clamped to it", "15");
  cl.flag("blend", "S", "blend from one local force model to the next over this time [s]", "0.003");
  cl.flag("fade", "S", "when the server stops answering or is gone, fade the rendered force to zero over this time [s]", "0.25");
  cl.flag("stale-after", "S", "a local force model this old means the server is not answering: start the fade [s]", "0.25");
  cl.flag("fade-in", "S", "after a jump (a claim, the organ reset, reloaded, paused or given another material) fade the force in over this time [s]",
          "0.1");
  cl.flag("slew-limit", "N_PER_MS",
          "the rendered force changes by at most this much per millisecond [N/ms], whatever the server sends (docs/FAULTS.md, \"The force "
          "on the hand\")",
          "1");
  cl.flag("tick-phase", "US", "send commands this long after each server tick [us] (at --rate = physics rate; negative: loop free)", "100");
  cl.option_switch("watch-mesh", "receive the organ's surface frames and report their rate and the surface's displacement");
  cl.option_switch("reconnect",
                   "when the server goes away, wait for one to come back and claim the instrument again; "
                   "when the instrument is freed under this client, claim it again");
  cl.option_switch("quiet", "no live lines, only the summary");
  cl.flag("report", "FILE.json", "write samples and statistics here (a new file; see --replace)");
  cl.option_switch("replace", "replace the --report file if it exists (never through a symbolic link)");
  try {
    if (!cl.parse(argc, argv)) return 0;
    const Options o = parse(cl);
    viscera::client::Client client(o.domain, o.client_id, o.station);
    const auto scene = client.wait_for_scene(std::chrono::seconds(10));
    if (!scene) {
      std::fprintf(stderr, "haptic-client: no viscera-server found in 10 s (same domain, --station and CYCLONEDDS_URI?)\n");
      return 3;
    }
    if (const auto claim = client.claim(o.instrument, std::chrono::seconds(5)); !claim) {
      std::fprintf(stderr, "haptic-client: instrument %u not claimed in scene %s: %s\n", o.instrument, scene->name.c_str(), claim.why.c_str());
      return 3;
    }
    const auto device = make_device(o, *scene);
    viscera::haptic::start_saying();  // from here the device loop runs: it never waits for the output
    struct StopSaying {
      ~StopSaying() { viscera::haptic::stop_saying(); }  // the queued lines out before the exit status
    } stop_saying;
    say("haptic-client: scene %s, instrument %u claimed; device: %s, %.0f Hz for %.1f s", scene->name.c_str(), o.instrument, device->name().c_str(),
        o.rate_hz, o.duration_s);
    const double start_epoch_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    const RunResult run = run_device(o, client, *device, scene->generation);
    if (!run.lost && run.instrument_lost_t_s < 0) client.release(o.instrument);
    const auto rtt = client.round_trip();
    say("haptic-client: %zu round trips: p50 %.0f us, p99 %.0f us, max %.0f us; %llu payloads rejected; %llu rendered forces clamped to %.1f N",
        rtt.samples, rtt.p50_us, rtt.p99_us, rtt.max_us, static_cast<unsigned long long>(client.rejected()),
        static_cast<unsigned long long>(run.clamps), o.max_force_n);
    if (run.longest_silence_end_t_s >= 0)
      say("haptic-client: the longest wait for a new force while driving: %.1f ms, ending at t = %.2f s", 1e3 * run.longest_silence_s,
          run.longest_silence_end_t_s);
    if (o.watch_mesh)
      say("haptic-client: %zu surface frames at %.1f Hz; surface generation %u, %zu vertices", run.mesh.frames, run.mesh.rate_hz(),
          run.mesh.generation, run.mesh.rest.size() / 3);
    if (run.phased > 0)
      say("haptic-client: commands timed %.0f us after the server's ticks in %llu periods, %.1f%% of them within 50 us", o.tick_phase_us,
          static_cast<unsigned long long>(run.phased), 100.0 * static_cast<double>(run.near_phase) / static_cast<double>(run.phased));
    viscera::haptic::stop_saying();  // before the lines on standard error
    if (!o.report.empty()) write_report(o, scene->name, device->name(), start_epoch_s, rtt, run);
    if (run.lost) {
      if (run.stall_end_t_s >= 0 && run.server_lost_t_s - run.stall_end_t_s < 0.5)
        std::fprintf(stderr,
                     "haptic-client: the server was not heard from at t = %.2f s, just after this process did not run for %.2f s (longer than "
                     "the lease): the server may be there still and have freed the instrument (--reconnect rides through stalls); the force "
                     "had faded to zero at t = %.2f s\n",
                     run.server_lost_t_s, run.stall_s, run.faded_t_s);
      else
        std::fprintf(stderr, "haptic-client: the server went away at t = %.2f s; the force had faded to zero at t = %.2f s\n", run.server_lost_t_s,
                     run.faded_t_s);
      return 4;
    }
    if (run.instrument_losses > 0 && run.instrument_lost_t_s < 0)
      std::fprintf(stderr, "haptic-client: instrument %u was freed under this client %d time(s) and claimed again (--reconnect)\n", o.instrument,
                   run.instrument_losses);
    if (run.instrument_lost_t_s >= 0) {
      std::fprintf(stderr, "haptic-client: instrument %u was no longer this client's at t = %.2f s; the force had faded to zero at t = %.2f s\n",
                   o.instrument, run.instrument_lost_t_s, run.faded_t_s);
      return 5;
    }
    return 0;
  } catch (const viscera::common::UsageError& e) {
    std::fprintf(stderr, "haptic-client: %s\n", e.what());
    return 2;
  } catch (const viscera::common::InputError& e) {
    std::fprintf(stderr, "haptic-client: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haptic-client: %s\n", e.what());
    return 1;
  }
}
