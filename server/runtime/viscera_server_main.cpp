// viscera-server: owns the organ and its solver and serves instruments over DDS.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>

#include "common/command_line.hpp"
#include "common/input_error.hpp"
#include "simulation_server.hpp"
#include "viscera/protocol/dds.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
}  // namespace

int main(int argc, char** argv) {
  viscera::cli::CommandLine cl("viscera-server",
      "Runs the tissue simulation of a scene (organ mesh, material, instruments; docs/SCENE.md) at its physics rate\n"
      "and serves instruments over Cyclone DDS (domain from the scene; configuration from CYCLONEDDS_URI, see\n"
      "deploy/cyclonedds.xml). Prints physics rate, step times, jitter and forces once a second. SIGINT/SIGTERM stop it.\n"
      "Clients may load another scene of the scene directory, change the material or the physics rate while it runs\n"
      "(viscera-control; docs/PROTOCOL.md).");
  cl.flag("scene", "FILE", "scene file (required)");
  cl.flag("scene-dir", "DIR", "scenes that clients may load by name (default: the scene file's directory)");
  cl.flag("duration", "S", "stop after S seconds; 0 runs until signalled", "0");
  cl.option_switch("quiet", "no status lines");
  std::string scene, scene_dir;
  double duration = 0;
  bool quiet = false;
  try {
    if (!cl.parse(argc, argv)) return 0;
    scene = cl.text("scene");
    if (cl.has("scene-dir")) {
      scene_dir = cl.text("scene-dir");
      if (!std::filesystem::is_directory(scene_dir))
        throw viscera::cli::UsageError("--scene-dir: '" + scene_dir + "' is not a directory");
    }
    duration = cl.number_in("duration", 0.0, 1e9);
    quiet = cl.has("quiet");
  } catch (const viscera::cli::UsageError& e) {
    std::fprintf(stderr, "viscera-server: %s\n", e.what());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    // Building a large organ takes seconds (the 96k liver about 3 s): say so before it starts.
    if (!quiet) {
      std::printf("viscera-server: loading %s\n", scene.c_str());
      std::fflush(stdout);
    }
    viscera::runtime::SimulationServer server(viscera::runtime::read_scene_file(scene), scene_dir);
    std::printf("viscera-server: %s\n", server.describe().c_str());
    std::fflush(stdout);
    const auto stats = server.run(g_stop, duration, [&](const std::string& line) {
      if (!quiet) {
        std::printf("viscera-server: %s\n", line.c_str());
        std::fflush(stdout);
      }
    });
    std::printf("viscera-server: stopped after %llu ticks, %llu late, %llu missed slots, %llu physics resets, %llu forces sent, %llu messages rejected, %llu mesh frames\n",
                static_cast<unsigned long long>(stats.ticks), static_cast<unsigned long long>(stats.late_ticks), static_cast<unsigned long long>(stats.missed_slots),
                static_cast<unsigned long long>(stats.physics_resets), static_cast<unsigned long long>(stats.forces_sent),
                static_cast<unsigned long long>(stats.rejected), static_cast<unsigned long long>(stats.mesh_frames));
    return 0;
  } catch (const viscera::tissue::InputError& e) {
    std::fprintf(stderr, "viscera-server: %s\n", e.what());
    return 2;
  } catch (const viscera::protocol::DdsError& e) {
    std::fprintf(stderr, "viscera-server: %s\n", e.what());
    return 3;
  }
}
