// viscera-control: session control of a running viscera-server from the command line, as an  // SPDX-License-Identifier: Apache-2.0
// instructor's console does it: pause, resume, reset the organ, load another scene, change the
// material or the physics rate, show the scene state, watch the server's health, follow the
// session's events, or annotate the session.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <thread>

#include "viscera/client/client.hpp"
#include "viscera/client/session_limits.hpp"
#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/protocol/dds.hpp"

namespace {

/// Text from the server (names from scene files and meshes, messages, annotations), printed with
/// every byte a terminal could act on escaped.
std::string shown(const std::string& text) { return viscera::common::printable(text, 400); }

/// Exit status when the server went away while watched.
constexpr int kServerGone = 4;

/// `change` with the material file at `path` (docs/MATERIAL.md), read and checked as JSON here:
/// the server checks its fields and answers naming the file. Its name travels as a plain name.
viscera::protocol::MaterialChange with_material_file(viscera::protocol::MaterialChange change, const std::string& path) {
  try {
    change.file_text = viscera::common::read_text_file(path, viscera::protocol::kMaxMaterialFileBytes);
    viscera::common::parse_json(*change.file_text, path);
  } catch (const viscera::common::InputError& e) {
    throw viscera::common::UsageError(std::string("--file: ") + e.what());
  }
  change.file_name = viscera::client::plain_file_name(path);
  return change;
}

/// True (after saying so) when the server is gone.
bool server_gone(viscera::client::Client& client) {
  if (client.server_state() != viscera::client::ServerState::lost) return false;
  std::fprintf(stderr, "viscera-control: the server is gone (its DDS liveliness lapsed or it left the domain)\n");
  return true;
}

/// Prints each health report of the server for `duration_s`, then the ticks, late ticks and
/// missed slots over the watched span (by the server's stamps). Returns 1 if no report came.
int watch_health(viscera::client::Client& client, const viscera::protocol::Scene& scene, double duration_s) {
  client.poll_telemetry();  // subscribe
  std::printf("watching the health of scene %s (physics %.0f Hz) for %.1f s\n", shown(scene.name).c_str(), scene.physics_rate_hz, duration_s);
  std::fflush(stdout);
  std::optional<viscera::protocol::TelemetryReport> first, last;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  while (std::chrono::steady_clock::now() < end) {
    if (server_gone(client)) return kServerGone;
    for (const auto& t : client.poll_telemetry()) {
      if (!first) first = t;
      last = t;
      std::printf(
          "t +%.4f s: %.0f Hz physics, %llu ticks (%llu late, %llu slots missed), step p50 %.0f us p99 %.0f us max %.0f us, "
          "tick jitter p99 %.0f us, %llu messages rejected (%llu malformed, %llu not from the owner, %llu for unknown instruments, %llu under "
          "another participant's client id)\n",
          1e-9 * static_cast<double>(t.server_stamp_ns - first->server_stamp_ns), t.physics_rate_hz, static_cast<unsigned long long>(t.steps),
          static_cast<unsigned long long>(t.late_ticks), static_cast<unsigned long long>(t.missed_slots), t.step_p50_us, t.step_p99_us, t.step_max_us,
          t.jitter_p99_us, static_cast<unsigned long long>(t.rejected_messages), static_cast<unsigned long long>(t.rejected_malformed),
          static_cast<unsigned long long>(t.rejected_not_owner), static_cast<unsigned long long>(t.rejected_unknown_instrument),
          static_cast<unsigned long long>(t.rejected_other_participant));
      std::fflush(stdout);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!first) {
    std::fprintf(stderr, "viscera-control: no health report from the server in %.1f s\n", duration_s);
    return 1;
  }
  if (last->steps < first->steps) {  // counters start again with a new server process
    std::printf("the server restarted while watched: no totals\n");
    return 0;
  }
  const double span_s = 1e-9 * static_cast<double>(last->server_stamp_ns - first->server_stamp_ns);
  std::printf("over %.3f s: %llu ticks, %llu late, %llu slots missed, %llu messages rejected\n", span_s,
              static_cast<unsigned long long>(last->steps - first->steps), static_cast<unsigned long long>(last->late_ticks - first->late_ticks),
              static_cast<unsigned long long>(last->missed_slots - first->missed_slots),
              static_cast<unsigned long long>(last->rejected_messages - first->rejected_messages));
  return 0;
}

/// What the command line asks for, checked before anything connects.
struct Request {
  std::string action, argument;
  viscera::protocol::MaterialChange change;
  double rate_hz = 0, duration_s = 10, seek_s = 0;
  std::chrono::milliseconds timeout{60'000};
  std::optional<std::uint64_t> seed;  ///< load: the drawn regions' seed
};

Request parse(const viscera::common::CommandLine& cl) {
  using viscera::common::UsageError;
  Request r;
  const auto& rest = cl.positional();
  const std::string actions = "pause, resume, reset, load SCENE, material, rate HZ, seek S, show, health, events or annotate TEXT";
  if (rest.empty()) throw UsageError("missing ACTION (" + actions + ")");
  r.action = rest[0];
  const std::map<std::string, bool> known = {{"pause", false},    {"resume", false},  {"reset", false}, {"load", true},
                                             {"material", false}, {"rate", true},     {"show", false},  {"health", false},
                                             {"events", false},   {"annotate", true}, {"seek", true}};
  const auto k = known.find(r.action);
  if (k == known.end()) throw UsageError("ACTION '" + r.action + "' is not " + actions);
  if (k->second != (rest.size() == 2)) throw UsageError(k->second ? r.action + " needs its argument" : "unexpected argument '" + rest.back() + "'");
  if (rest.size() == 2) r.argument = rest[1];
  if (r.action == "annotate" && r.argument.size() > viscera::client::kMaxAnnotationBytes)
    throw UsageError("TEXT is " + std::to_string(r.argument.size()) + " bytes (at most 1024)");
  for (const auto& p : viscera::client::material_parameters())
    if (cl.has(p.name)) {
      const double v = cl.number(p.name);
      if (const auto why = viscera::client::outside_range(std::string("--") + p.name, v, p.lo, p.hi)) throw UsageError(*why);
      r.change.*p.field = v;
    }
  if (cl.has("file") && r.action != "material") throw UsageError("material flags are for the material action");
  if (cl.has("file")) r.change = with_material_file(r.change, cl.text("file"));
  if ((r.action == "material") != !r.change.empty())
    throw UsageError(
        r.action == "material"
            ? "material needs --file or at least one of --youngs-modulus-pa, --poisson-ratio, --density-kg-m3, --shear-q, --damping-per-s"
            : "material flags are for the material action");
  if (r.action == "load") {
    if (!viscera::client::is_scene_name(r.argument)) throw UsageError(viscera::client::not_a_scene_name(r.argument));
    if (cl.has("seed")) r.seed = cl.integer_in("seed", 0, 9007199254740991);
  } else if (cl.has("seed")) {
    throw UsageError("--seed is for the load action");
  }
  if (r.action == "rate") {
    std::string why;
    const auto hz = viscera::common::read_integer(r.argument, &why);
    if (!hz) throw UsageError("rate: " + why + " of hertz");
    if (*hz < 10 || *hz > 10000) throw UsageError("rate: " + viscera::common::outside(*hz, 10LL, 10000LL) + " Hz");
    r.rate_hz = static_cast<double>(*hz);
  }
  if (r.action == "seek") {
    std::string why;
    const auto s = viscera::common::read_number(r.argument, &why);
    if (!s) throw UsageError("seek: " + why + " (a time from the recording's start [s])");
    if (*s < 0 || *s > 1e9) throw UsageError("seek: " + viscera::common::outside(*s, 0.0, 1e9) + " s");
    r.seek_s = *s;
  }
  r.duration_s = cl.number_in("duration", 0.1, 1e6);
  r.timeout = std::chrono::milliseconds(static_cast<long long>(1000 * cl.number_in("timeout", 0.1, 3600)));
  return r;
}

/// Prints the session's events and annotations for `duration_s`.
int follow_events(viscera::client::Client& client, const viscera::protocol::Scene& scene, double duration_s) {
  client.poll_events();  // subscribe
  std::printf("following the events of scene %s for %.1f s\n", shown(scene.name).c_str(), duration_s);
  std::fflush(stdout);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  while (std::chrono::steady_clock::now() < end) {
    if (server_gone(client)) return kServerGone;
    for (const auto& e : client.poll_events()) {
      std::printf("event %s tick %llu sim %.3f s instrument %u client %u%s%s\n", viscera::protocol::event_name(e.kind),
                  static_cast<unsigned long long>(e.tick), e.sim_time_s, e.instrument_id, e.client_id, e.text.empty() ? "" : ": ",
                  shown(e.text).c_str());
      std::fflush(stdout);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

/// load, material, rate (an outcome), or pause, resume, reset (the state confirms it). 0 when done.
int control(viscera::client::Client& client, const Request& r) {
  using viscera::protocol::Action;
  if (r.action == "load" || r.action == "material" || r.action == "rate" || r.action == "seek") {
    const auto outcome = r.action == "load"       ? client.load_scene(r.argument, r.timeout, r.seed)
                         : r.action == "material" ? client.set_material(r.change, r.timeout)
                         : r.action == "seek"     ? client.seek(r.seek_s, r.timeout)
                                                  : client.set_physics_rate(r.rate_hz, r.timeout);
    if (!outcome) {
      std::fprintf(stderr, "viscera-control: no outcome of '%s' from the server within %.1f s\n", r.action.c_str(),
                   1e-3 * static_cast<double>(r.timeout.count()));
      return 1;
    }
    if (!outcome->accepted) {
      std::fprintf(stderr, "viscera-control: refused: %s\n", shown(outcome->message).c_str());
      return 1;
    }
    std::printf("%s\n", shown(outcome->message).c_str());
    return 0;
  }
  const Action a = r.action == "pause" ? Action::pause : r.action == "resume" ? Action::resume : Action::reset;
  if (!client.control(a, std::chrono::seconds(5))) {
    std::fprintf(stderr, "viscera-control: the server did not confirm '%s' within 5 s\n", r.action.c_str());
    return 1;
  }
  return 0;
}

void print_scene(const viscera::protocol::Scene& scene) {
  std::printf("scene %s: %s, physics %.0f Hz, instruments:", shown(scene.name).c_str(), scene.paused ? "paused" : "running", scene.physics_rate_hz);
  for (const auto& i : scene.instruments)
    std::printf(" %u (%s, %s)", i.instrument_id,
                i.scalpel   ? "scalpel"
                : i.grasper ? "grasper"
                            : "probe",
                i.owner_client_id ? ("client " + std::to_string(i.owner_client_id)).c_str() : "free");
  const auto& m = scene.material;
  std::printf("\n  generation %u, material %s: E %.6g Pa, nu %.4g, density %.6g kg/m^3, shear Q %.4g, damping %.4g 1/s", scene.generation,
              shown(m.name).c_str(), m.youngs_modulus_pa, m.poisson_ratio, m.density_kg_m3, m.shear_q, m.damping_per_s);
  if (m.added_mass_fraction > 0) std::printf(", mass scaling +%.2f%% (smallest elements)", 100 * m.added_mass_fraction);
  std::printf("\n");
  std::string list;
  for (const auto& n : scene.available_scenes) list += " " + n;
  std::printf("  scenes to load:%s%s%s\n", list.empty() ? " (none)" : shown(list).c_str(), scene.preparing.empty() ? "" : "; preparing ",
              shown(scene.preparing).c_str());
  for (const auto& u : scene.unreadable_scenes) std::printf("  unreadable scene %s\n", shown(u).c_str());
  for (const auto& g : scene.regions) {
    if (g.shape == viscera::protocol::RegionShape::elements)
      std::printf("  region %s: tagged elements around (%.4g, %.4g, %.4g) m, within (%.4g, %.4g, %.4g)-(%.4g, %.4g, %.4g) m", shown(g.name).c_str(),
                  g.center[0], g.center[1], g.center[2], g.box_min[0], g.box_min[1], g.box_min[2], g.box_max[0], g.box_max[1], g.box_max[2]);
    else if (g.shape == viscera::protocol::RegionShape::box)
      std::printf("  region %s: box (%.4g, %.4g, %.4g)-(%.4g, %.4g, %.4g) m", shown(g.name).c_str(), g.box_min[0], g.box_min[1], g.box_min[2],
                  g.box_max[0], g.box_max[1], g.box_max[2]);
    else
      std::printf("  region %s: sphere of radius %.4g m at (%.4g, %.4g, %.4g) m, its top %.3g m deep", shown(g.name).c_str(), g.radius_m, g.center[0],
                  g.center[1], g.center[2], g.depth_m);
    std::printf(", %u elements, material %s (E %.0f Pa)\n", g.elements, shown(g.material_name).c_str(), g.youngs_modulus_pa);
  }
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl(
      "viscera-control",
      "Session control of a running viscera-server. ACTION is one of\n"
      "  pause           the organ stops; forces are still answered from its frozen state\n"
      "  resume, reset   reset: the organ back at rest, graspers let go\n"
      "  load SCENE      load a scene of the server's scene directory (show lists them); instruments are released\n"
      "  material        change material parameters (the flags below), or switch to a material file (--file, docs/MATERIAL.md:\n"
      "                  a lab's material.json); the organ keeps its deformation, its regions their materials\n"
      "  rate HZ         change the physics rate [Hz]\n"
      "  seek S          a replay (viscera-replay play, with --station): jump to S seconds from the recording's start\n"
      "  show            print the scene state\n"
      "  health          print the server's health reports (physics rate, step times, late ticks, missed slots,\n"
      "                  rejected messages) for --duration seconds, then what changed over them\n"
      "  events          print the session's events and annotations for --duration seconds\n"
      "  annotate TEXT   a note for recorders and consoles\n"
      "Exit status: 0 done, 1 refused or not confirmed, 2 bad arguments, 3 no server, 4 the server went away (health, events).");
  cl.usage("viscera-control ACTION [ARGUMENT] [--domain ID] [--station NAME] [--duration S] [material flags]");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("station", "NAME",
          "the station to act on: a live server's (viscera-server --station) or a replay's (viscera-replay play --station) to follow and steer it "
          "(default: none, the default partition)",
          "");
  cl.flag("client-id", "N", "this client's id (non-zero)", "900");
  cl.flag("duration", "S", "events, health: how long to follow them [s]", "10");
  cl.flag("timeout", "S", "load, material, rate: how long to wait for the server's outcome [s]", "60");
  cl.flag("seed", "N", "load: the seed of the scene's drawn material regions (a hidden nodule elsewhere; default: the scene file's)");
  cl.flag("file", "MATERIAL.json", "material: the organ's new material, a material file (at most 64 KiB); the parameter flags then change it");
  for (const auto& p : viscera::client::material_parameters()) cl.flag(p.name, p.value_name, std::string("material: ") + p.help);
  cl.allow_positional(2);
  try {
    if (!cl.parse(argc, argv)) return 0;
    const Request r = parse(cl);
    const std::string station = viscera::protocol::checked_station(cl.text("station"));
    viscera::client::Client client(static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230)),
                                   static_cast<std::uint32_t>(cl.integer_in("client-id", 1, 4000000000)), station);
    auto scene = client.wait_for_scene(std::chrono::seconds(10));
    if (!scene) {
      std::fprintf(stderr, "viscera-control: no viscera-server (or replay) found in 10 s (same domain, --station and CYCLONEDDS_URI?)\n");
      return 3;
    }
    if (r.action == "events") return follow_events(client, *scene, r.duration_s);
    if (r.action == "health") return watch_health(client, *scene, r.duration_s);
    if (r.action == "annotate") {
      client.annotate(r.argument);  // waits for the readers' acknowledgements
      std::printf("annotated scene %s\n", shown(scene->name).c_str());
      return 0;
    }
    if (r.action != "show") {
      if (const int rc = control(client, r); rc != 0) return rc;
      scene = client.wait_for_scene(std::chrono::seconds(1));
    }
    print_scene(*scene);
    return 0;
  } catch (const viscera::common::UsageError& e) {
    std::fprintf(stderr, "viscera-control: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-control: %s\n", e.what());
    return 1;
  }
}
