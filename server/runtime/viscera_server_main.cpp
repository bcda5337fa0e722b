// viscera-server: owns the organ and its solver and serves instruments over DDS.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "common/input_error.hpp"
#include "simulation_server.hpp"
#include "viscera/protocol/dds.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
const char* kHelp =
    "Usage: viscera-server --scene FILE.json [--scene-dir DIR] [--duration S] [--quiet]\n\n"
    "Runs the tissue simulation of a scene (organ mesh, material, instruments; docs/SCENE.md) at its physics rate\n"
    "and serves instruments over Cyclone DDS (domain from the scene; configuration from CYCLONEDDS_URI, see\n"
    "deploy/cyclonedds.xml). Prints physics rate, step times, jitter and forces once a second. SIGINT/SIGTERM stop it.\n"
    "Clients may load another scene of the scene directory, change the material or the physics rate while it runs\n"
    "(viscera-control; docs/PROTOCOL.md).\n\n"
    "Options:\n  --scene FILE    scene file (required)\n  --scene-dir DIR scenes that clients may load by name (default: the scene file's directory)\n  --duration S    stop after S seconds (default: run until signalled)\n"
    "  --quiet         no status lines\n  --help          this text\n";
}  // namespace

int main(int argc, char** argv) {
  std::string scene, scene_dir;
  double duration = 0;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help") {
      std::fputs(kHelp, stdout);
      return 0;
    } else if (a == "--scene" && i + 1 < argc) {
      scene = argv[++i];
    } else if (a == "--scene-dir" && i + 1 < argc) {
      scene_dir = argv[++i];
      if (!std::filesystem::is_directory(scene_dir)) {
        std::fprintf(stderr, "viscera-server: --scene-dir: '%s' is not a directory\n", scene_dir.c_str());
        return 2;
      }
    } else if (a == "--duration" && i + 1 < argc) {
      char* end = nullptr;
      duration = std::strtod(argv[++i], &end);
      if (*end || !(duration >= 0)) {
        std::fprintf(stderr, "viscera-server: --duration: '%s' is not a non-negative number of seconds\n", argv[i]);
        return 2;
      }
    } else if (a == "--quiet") {
      quiet = true;
    } else {
      std::fprintf(stderr, "viscera-server: unknown or incomplete option '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (scene.empty()) {
    std::fprintf(stderr, "viscera-server: --scene FILE is required (see --help)\n");
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
    std::printf("viscera-server: stopped after %llu ticks, %llu overruns, %llu physics resets, %llu forces sent, %llu messages rejected, %llu mesh frames\n",
                static_cast<unsigned long long>(stats.ticks), static_cast<unsigned long long>(stats.overruns),
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
