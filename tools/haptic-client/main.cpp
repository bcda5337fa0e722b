// haptic-client: a virtual haptic device playing a scripted probe trajectory against a running
// viscera-server: claims an instrument, streams the tip position at the device rate, receives
// the tissue's force, prints force and round-trip latency, and writes a JSON report.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/command_line.hpp"
#include "viscera/client/client.hpp"
#include "viscera/client/local_force_model.hpp"

#include <map>

int main(int argc, char** argv) {
  viscera::cli::CommandLine cl("haptic-client",
      "A virtual haptic device: claims an instrument of a running viscera-server and plays a scripted trajectory.\n"
      "Script 'press': the probe starts 1 cm above the organ at the centre of its top, presses down to DEPTH below\n"
      "the top of the bounding box in the first half of the run and comes back in the second half.\n"
      "Prints force and command-to-force round trip; --report writes every sample as JSON.");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("client-id", "N", "this client's id (non-zero, unique per client)", "1");
  cl.flag("instrument", "ID", "instrument to claim", "1");
  cl.flag("duration", "S", "length of the run [s]", "4");
  cl.flag("rate", "HZ", "device rate [Hz]", "1000");
  cl.flag("depth", "M", "press depth below the top of the organ's bounding box [m]", "0.03");
  cl.flag("script", "NAME", "press (probe) | grasp (grasper: touch the top, close the jaws, pull up PULL, open)", "press");
  cl.flag("pull", "M", "grasp script: how far to pull up after grasping [m]", "0.02");
  cl.flag("max-force", "N", "device force limit [N]; rendered forces are clamped to it", "15");
  cl.flag("report", "FILE.json", "write samples and statistics here");
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto client_id = static_cast<std::uint32_t>(cl.number_in("client-id", 1, 4e9));
    const auto instrument = static_cast<std::uint32_t>(cl.number_in("instrument", 1, 1e6));
    const double duration = cl.number_in("duration", 0.1, 3600), rate = cl.number_in("rate", 1, 20000), depth = cl.number_in("depth", 0, 0.2);
    const double max_force = cl.number_in("max-force", 0.1, 1000), pull = cl.number_in("pull", 0, 0.2);
    const std::string script = cl.text("script");
    if (script != "press" && script != "grasp") throw viscera::cli::UsageError("--script: '" + script + "' is not press or grasp");
    std::map<std::uint64_t, viscera::protocol::Vector3> sent;  // tip of each recent command, for the local model
    std::uint64_t seq = 0, clamps = 0;
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
    const double cx = 0.5 * (scene->bounds_min[0] + scene->bounds_max[0]), cy = 0.5 * (scene->bounds_min[1] + scene->bounds_max[1]);
    const double top = scene->bounds_max[2];
    std::printf("haptic-client: scene %s, instrument %u claimed; script %s at (%.3f, %.3f), from z = %.3f m down to %.3f m\n",
                scene->name.c_str(), instrument, script.c_str(), cx, cy, top + 0.01, top - depth);
    std::fflush(stdout);
    nlohmann::json samples = nlohmann::json::array();
    const auto period = std::chrono::nanoseconds(static_cast<long long>(1e9 / rate));
    const auto start = std::chrono::steady_clock::now();
    auto next = start;
    double last_print = -1;
    for (;;) {
      const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (t >= duration) break;
      const double phase = t / duration;  // 0..1
      double z = 0, jaw = 0.5;
      if (script == "press") {  // down then up
        z = (top + 0.01) - (0.01 + depth) * (phase < 0.5 ? 2 * phase : 2 * (1 - phase));
      } else {  // grasp: 0-0.25 descend to the surface, close; 0.25-0.75 pull up; 0.75-1 open and hold
        const double surface = top - depth;
        if (phase < 0.25) z = (top + 0.01) - (top + 0.01 - surface) * (phase / 0.25);
        else if (phase < 0.75) z = surface + pull * (phase - 0.25) / 0.5;
        else z = surface + pull;
        jaw = (phase >= 0.2 && phase < 0.75) ? 0.0 : 0.5;
      }
      client.send_tip(instrument, {cx, cy, z}, jaw);
      sent[++seq] = {cx, cy, z};
      if (sent.size() > 4096) sent.erase(sent.begin());
      // Wait for the answer to this command until shortly before the next device period.
      if (const auto f = client.wait_force(instrument, next + period - std::chrono::microseconds(100))) {
        // The force rendered now, from the server's latest local model at the current tip.
        const auto it = sent.find(f->command_seq);
        const auto rendered = it != sent.end() ? viscera::client::render_local_model(*f, it->second, {cx, cy, z}, max_force)
                                               : viscera::client::RenderedForce{};
        clamps += rendered.clamped;
        samples.push_back({{"t_s", t}, {"tip_z_m", z}, {"jaw_rad", jaw}, {"force_n", {f->force[0], f->force[1], f->force[2]}}, {"in_contact", f->in_contact},
                           {"rendered_force_n", {rendered.force[0], rendered.force[1], rendered.force[2]}},
                           {"model_age_commands", seq - f->command_seq}, {"command_seq", f->command_seq}});
        if (t - last_print >= 0.25) {
          std::printf("t = %5.2f s  tip z %.4f m  force (%.3f, %.3f, %.3f) N%s\n", t, z, f->force[0], f->force[1], f->force[2],
                      f->in_contact ? "  contact" : "");
          last_print = t;
          std::fflush(stdout);
        }
      }
      next += period;
      std::this_thread::sleep_until(next);
    }
    client.release(instrument);
    const auto rtt = client.round_trip();
    std::printf("haptic-client: %zu round trips: p50 %.0f us, p99 %.0f us, max %.0f us; %llu payloads rejected; %llu rendered forces clamped to %.1f N\n",
                rtt.samples, rtt.p50_us, rtt.p99_us, rtt.max_us, static_cast<unsigned long long>(client.rejected()),
                static_cast<unsigned long long>(clamps), max_force);
    if (cl.has("report")) {
      nlohmann::json r{{"scene", scene->name}, {"instrument", instrument}, {"client_id", client_id}, {"rate_hz", rate},
                       {"duration_s", duration}, {"round_trip_us", {{"samples", rtt.samples}, {"p50", rtt.p50_us}, {"p99", rtt.p99_us}, {"max", rtt.max_us}}},
                       {"samples", samples}};
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
