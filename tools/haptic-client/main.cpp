// haptic-client: a virtual haptic device playing a scripted probe trajectory against a running
// viscera-server: claims an instrument, streams the tip position at the device rate, receives
// the tissue's force, prints force and round-trip latency, and writes a JSON report.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/command_line.hpp"
#include "viscera/client/client.hpp"
#include "viscera/client/local_force_model.hpp"

int main(int argc, char** argv) {
  viscera::cli::CommandLine cl("haptic-client",
      "A virtual haptic device: claims an instrument of a running viscera-server and plays a scripted trajectory.\n"
      "Script 'press': the probe starts 1 cm above the organ at the centre of its top and moves down until the\n"
      "server reports contact, presses DEPTH further by mid-run and comes back to the contact height by the end.\n"
      "Script 'grasp': the grasper moves down to contact (plus DEPTH), closes its jaws, pulls up PULL, opens.\n"
      "Prints force and command-to-force round trip; --report writes every sample as JSON.");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("client-id", "N", "this client's id (non-zero, unique per client)", "1");
  cl.flag("instrument", "ID", "instrument to claim", "1");
  cl.flag("duration", "S", "length of the run [s]", "4");
  cl.flag("rate", "HZ", "device rate [Hz]", "1000");
  cl.flag("depth", "M", "how far to press beyond the first contact [m]", "0.03");
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
    // Search: down from 1 cm above the organ at a speed that reaches its bottom in 40% of the run.
    const double search_speed = (top + 0.01 - scene->bounds_min[2]) / (0.4 * duration);
    double contact_z = std::numeric_limits<double>::quiet_NaN(), contact_t = 0;
    std::printf("haptic-client: scene %s, instrument %u claimed; script %s at (%.3f, %.3f), from z = %.3f m down to contact%s%.3f m\n",
                scene->name.c_str(), instrument, script.c_str(), cx, cy, top + 0.01, " + ", depth);
    std::fflush(stdout);
    nlohmann::json samples = nlohmann::json::array();
    const auto period = std::chrono::nanoseconds(static_cast<long long>(1e9 / rate));
    const auto start = std::chrono::steady_clock::now();
    auto next = start;
    double last_print = -1;
    for (;;) {
      const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (t >= duration) break;
      double z = 0, jaw = 0.5;
      if (std::isnan(contact_z)) {  // searching for the surface (sags under gravity, moves under other tools)
        z = std::max(scene->bounds_min[2], top + 0.01 - search_speed * t);
      } else if (script == "press") {  // DEPTH beyond contact by mid-run, back to the contact height at the end
        const double mid = std::max(0.5 * duration, contact_t + 1e-3);
        z = t < mid ? contact_z - depth * (t - contact_t) / (mid - contact_t) : contact_z - depth * (duration - t) / (duration - mid);
      } else {  // grasp: DEPTH beyond contact within 5% of the run, jaws closed; pull up PULL by 75%; open and hold
        const double bite = contact_z - depth, t1 = contact_t + 0.05 * duration, t2 = std::max(0.75 * duration, t1 + 1e-3);
        if (t < t1) z = contact_z - depth * (t - contact_t) / (t1 - contact_t);
        else if (t < t2) z = bite + pull * (t - t1) / (t2 - t1);
        else z = bite + pull;
        jaw = t < t2 ? 0.0 : 0.5;
      }
      client.send_tip(instrument, {cx, cy, z}, jaw);
      sent[++seq] = {cx, cy, z};
      if (sent.size() > 4096) sent.erase(sent.begin());
      // Wait for the answer to this command until shortly before the next device period.
      if (const auto f = client.wait_force(instrument, next + period - std::chrono::microseconds(100))) {
        if (std::isnan(contact_z) && f->in_contact) {
          contact_z = z;
          contact_t = t;
          std::printf("t = %5.2f s  contact at tip z %.4f m\n", t, z);
        }
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
