// viscera-control: session control of a running viscera-server from the command line, as an
// instructor's console does it: pause, resume, reset the organ, or show the scene state.
#include <chrono>
#include <cstdio>

#include "common/command_line.hpp"
#include "viscera/client/client.hpp"

int main(int argc, char** argv) {
  viscera::cli::CommandLine cl("viscera-control",
      "Session control of a running viscera-server: ACTION is pause (the organ stops; forces are still answered from its\n"
      "frozen state), resume, reset (the organ back at rest, graspers let go) or show (print the scene state).\n"
      "Usage: viscera-control ACTION [--domain ID]");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("client-id", "N", "this client's id (non-zero)", "900");
  cl.allow_positional(1);
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto& rest = cl.positional();
    if (rest.size() != 1) throw viscera::cli::UsageError("expected one ACTION (pause, resume, reset or show), got " + std::to_string(rest.size()));
    const std::string action = rest[0];
    if (action != "pause" && action != "resume" && action != "reset" && action != "show")
      throw viscera::cli::UsageError("ACTION '" + action + "' is not pause, resume, reset or show");
    viscera::client::Client client(static_cast<std::uint32_t>(cl.number_in("domain", 0, 230)),
                                   static_cast<std::uint32_t>(cl.number_in("client-id", 1, 4e9)));
    auto scene = client.wait_for_scene(std::chrono::seconds(10));
    if (!scene) {
      std::fprintf(stderr, "viscera-control: no viscera-server found in 10 s (same domain and CYCLONEDDS_URI?)\n");
      return 3;
    }
    using viscera::protocol::Action;
    if (action != "show") {
      const Action a = action == "pause" ? Action::pause : action == "resume" ? Action::resume : Action::reset;
      if (!client.control(a, std::chrono::seconds(5))) {
        std::fprintf(stderr, "viscera-control: the server did not confirm '%s' within 5 s\n", action.c_str());
        return 1;
      }
      scene = client.wait_for_scene(std::chrono::seconds(1));
    }
    std::printf("scene %s: %s, physics %.0f Hz, instruments:", scene->name.c_str(), scene->paused ? "paused" : "running", scene->physics_rate_hz);
    for (const auto& i : scene->instruments)
      std::printf(" %u (%s, %s)", i.instrument_id, i.grasper ? "grasper" : "probe",
                  i.owner_client_id ? ("client " + std::to_string(i.owner_client_id)).c_str() : "free");
    std::printf("\n");
    return 0;
  } catch (const viscera::cli::UsageError& e) {
    std::fprintf(stderr, "viscera-control: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-control: %s\n", e.what());
    return 1;
  }
}
