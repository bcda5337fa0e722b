// viscera-control: session control of a running viscera-server from the command line, as an
// instructor's console does it: pause, resume, reset the organ, show the scene state, follow the
// session's events, or annotate the session.
#include <chrono>
#include <cstdio>
#include <thread>

#include "common/command_line.hpp"
#include "viscera/client/client.hpp"

int main(int argc, char** argv) {
  viscera::cli::CommandLine cl("viscera-control",
      "Session control of a running viscera-server: ACTION is pause (the organ stops; forces are still answered from its\n"
      "frozen state), resume, reset (the organ back at rest, graspers let go), show (print the scene state), events\n"
      "(print the session's events and annotations for --duration seconds) or annotate TEXT (a note for recorders).\n"
      "Usage: viscera-control ACTION [TEXT] [--domain ID] [--duration S]");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("client-id", "N", "this client's id (non-zero)", "900");
  cl.flag("duration", "S", "events: how long to follow them [s]", "10");
  cl.allow_positional(2);
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto& rest = cl.positional();
    if (rest.empty()) throw viscera::cli::UsageError("missing ACTION (pause, resume, reset, show, events or annotate TEXT)");
    const std::string action = rest[0];
    if (action != "pause" && action != "resume" && action != "reset" && action != "show" && action != "events" && action != "annotate")
      throw viscera::cli::UsageError("ACTION '" + action + "' is not pause, resume, reset, show, events or annotate");
    if ((action == "annotate") != (rest.size() == 2))
      throw viscera::cli::UsageError(action == "annotate" ? "annotate needs the TEXT" : "unexpected argument '" + rest.back() + "'");
    if (action == "annotate" && rest[1].size() > 1024) throw viscera::cli::UsageError("TEXT is " + std::to_string(rest[1].size()) + " bytes (at most 1024)");
    const double duration = cl.number_in("duration", 0.1, 1e6);
    viscera::client::Client client(static_cast<std::uint32_t>(cl.number_in("domain", 0, 230)),
                                   static_cast<std::uint32_t>(cl.number_in("client-id", 1, 4e9)));
    auto scene = client.wait_for_scene(std::chrono::seconds(10));
    if (!scene) {
      std::fprintf(stderr, "viscera-control: no viscera-server found in 10 s (same domain and CYCLONEDDS_URI?)\n");
      return 3;
    }
    using viscera::protocol::Action;
    if (action == "events") {
      client.poll_events();  // subscribe
      std::printf("following the events of scene %s for %.1f s\n", scene->name.c_str(), duration);
      std::fflush(stdout);
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
      while (std::chrono::steady_clock::now() < end) {
        for (const auto& e : client.poll_events()) {
          std::printf("event %s sim %.3f s instrument %u client %u%s%s\n", viscera::protocol::event_name(e.kind), e.sim_time_s, e.instrument_id,
                      e.client_id, e.text.empty() ? "" : ": ", e.text.c_str());
          std::fflush(stdout);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      return 0;
    }
    if (action == "annotate") {
      client.annotate(rest[1]);  // waits for the readers' acknowledgements
      std::printf("annotated scene %s\n", scene->name.c_str());
      return 0;
    }
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
