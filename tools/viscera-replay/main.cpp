// viscera-replay: plays a recorded session back onto a DDS partition of its own, or re-simulates  // SPDX-License-Identifier: Apache-2.0
// it in lockstep and compares every force and frame (docs/RECORDING.md).
#include <atomic>
#include <csignal>
#include <cstdio>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/process/child_process.hpp"
#include "viscera/protocol/dds.hpp"

#include "play.hpp"
#include "resimulate.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
}  // namespace

int main(int argc, char** argv) {
  using viscera::common::UsageError;
  viscera::common::CommandLine cl(
      "viscera-replay",
      "Plays a session recording (viscera-record) back, or re-simulates it (docs/RECORDING.md).\n"
      "  play FILE.mcap         publishes the recording again at its original pace times --rate, as the station\n"
      "                         --station (never a live one: a replay must not drive a live server's instruments).\n"
      "                         Follow it with viscera-control --station NAME. Space pauses and resumes, left and\n"
      "                         right seek 5 s, q quits (on a terminal); pause, resume and seek session requests sent\n"
      "                         to the replayer do the same (viscera-control pause|resume|seek S --station NAME).\n"
      "  resimulate FILE.mcap   starts a fresh viscera-server in lockstep on the recorded scene (or --scene), feeds it\n"
      "                         the recorded commands and requests at the ticks the original applied them, and compares\n"
      "                         every force, event and surface frame. Exit 0: bit-identical; 1: diverged (the first\n"
      "                         divergence is named: tick, topic, field, recorded and recomputed values).\n"
      "Exit status 2: bad arguments or a recording that cannot be used (one line says why); 3: DDS or the server failed.");
  cl.usage(
      "viscera-replay play FILE.mcap [--rate R] [--loop] [--from S] [--to S] [--station NAME] | resimulate FILE.mcap [--report OUT.json "
      "[--replace]]");
  cl.flag("rate", "R", "play: pace, times the original", "1");
  cl.option_switch("loop", "play: start again at --from after --to");
  cl.flag("from", "S", "play: from this time of the recording [s]", "0");
  cl.flag("to", "S", "play: to this time of the recording [s] (default: its end)");
  cl.flag("station", "NAME", "play: the station (DDS partition) to publish as, never a live server's", "viscera-replay");
  cl.flag("domain", "ID", "DDS domain (default: the recording's)");
  cl.option_switch("no-keys", "play: ignore the terminal's keys");
  cl.flag("report", "OUT.json", "resimulate: write the report here (a new file; see --replace)");
  cl.option_switch("replace", "resimulate: replace the --report file if it exists (never through a symbolic link)");
  cl.flag("scene", "FILE", "resimulate: this scene file instead of the recorded one (same organ; material, model, damping may differ)");
  cl.flag("server", "PATH", "resimulate: the viscera-server program (default: the one beside this program)");
  cl.option_switch("quiet", "no progress lines");
  cl.allow_positional(2);
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto& args = cl.positional();
    if (args.size() != 2 || (args[0] != "play" && args[0] != "resimulate"))
      throw UsageError("expected: play FILE.mcap | resimulate FILE.mcap (see --help)");
    std::optional<std::uint32_t> domain;
    if (cl.has("domain")) domain = static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230));
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    if (args[0] == "play") {
      viscera::replay::PlayOptions o;
      o.recording = args[1];
      o.rate = cl.number_in("rate", 0.01, 1000);
      o.loop = cl.has("loop");
      o.from_s = cl.number_in("from", 0, 1e9);
      if (cl.has("to")) o.to_s = cl.number_in("to", 0, 1e9);
      o.partition = viscera::protocol::checked_station(cl.text("station"));  // the SDK's StreamPublisher refuses the same
      if (o.partition.empty()) throw UsageError("--station: a replay publishes as a station of its own, not in the default partition");
      o.domain = domain;
      o.keys = !cl.has("no-keys");
      o.quiet = cl.has("quiet");
      return viscera::replay::play(o, g_stop);
    }
    viscera::replay::ResimulateOptions o;
    o.recording = args[1];
    if (cl.has("scene")) o.scene = cl.text("scene");
    if (cl.has("report")) o.report = cl.text("report");
    o.replace_report = cl.has("replace");
    o.server = cl.has("server") ? cl.text("server") : viscera::process::find_program("viscera-server", "server/runtime");
    o.domain = domain;
    o.quiet = cl.has("quiet");
    return viscera::replay::resimulate(o, g_stop);
  } catch (const viscera::replay::Interrupted& e) {
    std::fprintf(stderr, "viscera-replay: %s\n", e.what());
    return 130;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-replay: %s\n", e.what());
    return 2;
  } catch (const viscera::common::InputError& e) {
    std::fprintf(stderr, "viscera-replay: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {  // a partition the SDK refuses to replay into
    std::fprintf(stderr, "viscera-replay: --station: %s\n", e.what());
    return 2;
  } catch (const viscera::protocol::DdsError& e) {
    std::fprintf(stderr, "viscera-replay: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-replay: %s\n", e.what());
    return 3;
  }
}
