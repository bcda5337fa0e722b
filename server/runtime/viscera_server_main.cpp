// viscera-server: owns the organ and its solver and serves instruments over DDS.  // SPDX-License-Identifier: Apache-2.0
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <sys/prctl.h>
#include <unistd.h>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/program_log.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/runtime/simulation_server.hpp"

namespace {
std::atomic<bool> g_stop{false};
std::atomic<bool> g_running{false};
// While the organ is being built (seconds for the 96k liver) a stop ends the process at once; once
// the physics runs, it sets the flag, which the loop checks between ticks and sub-steps.
void on_signal(int sig) {
  if (!g_running.load()) {
    constexpr char msg[] = "viscera-server: stopped while loading\n";
    [[maybe_unused]] const auto n = ::write(2, msg, sizeof msg - 1);
    ::_exit(128 + sig);
  }
  g_stop = true;
}
}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl(
      "viscera-server",
      "Runs the tissue simulation of a scene (organ mesh, material, instruments; docs/SCENE.md) at its physics rate\n"
      "and serves instruments over Cyclone DDS (domain from the scene; configuration from CYCLONEDDS_URI, see\n"
      "deploy/dds/loopback.xml). Prints physics rate, step times, jitter and forces once a second. SIGINT/SIGTERM stop it.\n"
      "Clients may load another scene of the scene directory, change the material or the physics rate while it runs\n"
      "(viscera-control; docs/PROTOCOL.md). With --lockstep it runs no clock of its own: a driver (viscera-replay\n"
      "resimulate) sends each tick and reads what it produced (docs/RECORDING.md).");
  cl.flag("scene", "FILE", "scene file (required)");
  cl.flag("scene-dir", "DIR", "scenes that clients may load by name (default: the scene file's directory)");
  cl.flag("domain", "N", "the DDS domain, 0-230 (default: the scene file's domain_id)");
  cl.flag("duration", "S", "stop after S seconds; 0 runs until signalled", "0");
  cl.flag("max-tick-ms", "MS", "longest a physics tick may take on this machine [ms]: a scene, material or rate needing more is refused", "100");
  cl.flag(
      "station", "NAME",
      "this trainee station's name: the DDS partition of every stream, so that several servers share a domain (default: none, the default partition)",
      "");
  cl.option_switch("lockstep", "ticks advance when a driver says so (deterministic; no tick budget unless --max-tick-ms is given)");
  cl.flag("log-file", "FILE", "append the log's lines to this file too (a service's log)", "");
  cl.option_switch("quiet", "no status lines");
  std::string scene, scene_dir;
  double duration = 0;
  viscera::runtime::TickBudget budget;
  bool quiet = false, lockstep = false;
  std::optional<std::uint32_t> domain;
  std::string station;
  try {
    if (!cl.parse(argc, argv)) return 0;
    scene = cl.text("scene");
    if (cl.has("scene-dir")) {
      scene_dir = cl.text("scene-dir");
      if (!std::filesystem::is_directory(scene_dir)) throw viscera::common::UsageError("--scene-dir: '" + scene_dir + "' is not a directory");
    }
    duration = cl.number_in("duration", 0.0, 1e9);
    budget.max_tick_s = 1e-3 * cl.number_in("max-tick-ms", 0.1, 10000);
    quiet = cl.has("quiet");
    lockstep = cl.has("lockstep");
    if (cl.has("domain")) domain = static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230));
    station = viscera::protocol::checked_station(cl.text("station"));
    if (lockstep && !cl.given("max-tick-ms")) budget.max_tick_s = 1e9;  // no real time to keep
  } catch (const viscera::common::UsageError& e) {
    std::fprintf(stderr, "viscera-server: %s\n", e.what());
    return 2;
  }
  std::shared_ptr<spdlog::logger> log;
  try {
    // Lines go out on a thread of their own: the physics thread, which reports once a second, never
    // waits for a slow disk or a full pipe (docs/FAULTS.md, "Output that blocks").
    log = viscera::common::program_log("viscera-server", cl.text("log-file"), {scene}, viscera::common::LogDelivery::background);
  } catch (const viscera::common::InputError& e) {
    std::fprintf(stderr, "viscera-server: %s\n", e.what());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  // A lockstep server serves the driver that started it: it dies with that process, even by
  // SIGKILL (which runs nothing of the driver's), instead of waiting for steps for ever. At once:
  // a re-simulation has nothing to save, and leaving the DDS domain cleanly took seconds.
  if (lockstep) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() == 1) std::raise(SIGKILL);  // the driver died before the line above
  }
  try {
    // Building a large organ takes seconds (the 96k liver about 3 s): say so before it starts.
    if (!quiet) log->info("loading {}", scene);
    viscera::runtime::SceneSpec spec = viscera::runtime::read_scene_file(scene);
    if (domain) spec.domain_id = *domain;
    viscera::runtime::DdsEndpoints endpoints(spec.domain_id, station, lockstep);
    auto server = std::make_unique<viscera::runtime::SimulationServer>(spec, endpoints, scene_dir, budget, lockstep);
    log->info("{}{}{}", lockstep ? "lockstep, " : "", server->describe(), station.empty() ? "" : ", station " + station);
    log->info("client ids bound to {}", endpoints.authenticated() ? "the certificate that first uses each (DDS Security in CYCLONEDDS_URI)"
                                                                  : "the DDS participant using each while it talks (no DDS Security configured)");
    g_running = true;
    const auto status = [&](const std::string& line) {
      if (!quiet) log->info("{}", line);
    };
    const auto stats = lockstep ? server->run_lockstep(g_stop, endpoints, status) : server->run(g_stop, duration, status);
    log->info(
        "stopped after {} ticks, {} late, {} missed slots, {} physics resets, {} forces sent, {} messages rejected "
        "(malformed {}, not owner {}, unknown instrument {}, another participant's client id {}), {} mesh frames; "
        "{} changes of the mesh by cuts, kinetic plus elastic energy rose at {} (largest change {:.3g} J)",
        stats.ticks, stats.late_ticks, stats.missed_slots, stats.physics_resets, stats.forces_sent, stats.rejected, stats.rejected_malformed,
        stats.rejected_not_owner, stats.rejected_unknown_instrument, stats.rejected_other_participant, stats.mesh_frames, stats.cut_changes,
        stats.cut_energy_rises, stats.cut_energy_change_max_j);
    if (const std::size_t dropped = viscera::common::log_lines_dropped(); dropped > 0)
      log->warn("{} log lines were dropped: standard output or the log file did not keep up", dropped);
    server.reset();  // leaves the DDS domain: clients see the server gone at once
    if (viscera::runtime::SimulationServer::abandoned_work() > 0) {
      // An organ still being built in the background is not waited for.
      log.reset();  // writes the queued lines
      std::quick_exit(0);
    }
    return 0;
  } catch (const viscera::common::InputError& e) {
    log->error("{}", e.what());
    return 2;
  } catch (const viscera::protocol::DdsError& e) {
    log->error("{}", e.what());
    return 3;
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
}
