// viscera-trainer: runs a training exercise on a live session and scores it, or scores a recorded  // SPDX-License-Identifier: Apache-2.0
// session afterwards with the same numbers (docs/TRAINING.md).
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <thread>

#include "viscera/client/client.hpp"
#include "viscera/client/stream_tap.hpp"
#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/recording/recording.hpp"
#include "viscera/training/exercise_scorer.hpp"

namespace {

namespace proto = viscera::protocol;
using viscera::training::Exercise;
using viscera::training::ExerciseScorer;
using viscera::training::ScoreReport;

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

/// Forces and events are processed this many ticks behind the newest force (a force may arrive
/// after the next tick's; the order must be the recording's).
constexpr std::uint64_t kMarginTicks = 200;
/// No force for this long: what is pending is all there is for now.
constexpr std::chrono::milliseconds kQuiet{300};

/// The report as JSON and Markdown in `dir` (if given), the summary on stdout; exit status 0
/// passed, 1 failed.
/// The report's files in `dir`: EXERCISE.json and EXERCISE.md (the name is a plain name).
std::vector<std::string> report_files(const std::string& dir, const std::string& exercise) {
  return {dir + "/" + exercise + ".json", dir + "/" + exercise + ".md"};
}

int conclude(const ScoreReport& r, const std::string& dir) {
  const std::string md = to_markdown(r);
  std::printf("%s", md.c_str());
  if (!dir.empty()) {
    const std::string base = dir + "/" + r.exercise;  // the folder was made before the work (main)
    viscera::common::write_file_text(base + ".json", to_json(r).dump(2) + "\n");
    viscera::common::write_file_text(base + ".md", md);
    std::printf("report: %s.json, %s.md\n", viscera::common::printable(base, 200).c_str(), viscera::common::printable(base, 200).c_str());
  }
  return r.passed ? 0 : 1;
}

int score(const Exercise& exercise, const std::string& path, const std::string& dir) {
  viscera::recording::Recording recording(path);
  ExerciseScorer scorer(exercise);
  std::uint64_t taken = 0;
  // As a live run does: a margin behind the newest tick, so a long recording is not held whole.
  recording.for_each([&](const viscera::recording::RecordedChannel& ch, const viscera::mcap::Message& m) {
    scorer.take(ch.stream, m.data);
    if (++taken % 1000 == 0 && scorer.newest_tick() > kMarginTicks) scorer.advance(scorer.newest_tick() - kMarginTicks);
    return !scorer.ended();
  });
  scorer.finish();
  for (const auto& line : scorer.take_feedback()) std::printf("trainer: %s\n", line.c_str());
  return conclude(scorer.report(), dir);
}

int run(const Exercise& exercise, std::uint32_t domain, const std::string& station, std::optional<std::uint64_t> seed, std::uint32_t client_id,
        const std::string& dir) {
  viscera::client::StreamTap tap(
      domain, station, {proto::Stream::instrument_command, proto::Stream::force_feedback, proto::Stream::event, proto::Stream::scene_state});
  viscera::client::Client client(domain, client_id, station);
  if (!client.wait_for_scene(std::chrono::seconds(10))) {
    std::fprintf(stderr, "viscera-trainer: no viscera-server found in 10 s (same domain, --station and CYCLONEDDS_URI?)\n");
    return 3;
  }
  ExerciseScorer scorer(exercise);
  // The tap must hear the scene's loading: wait until it has the server's scene state (transient
  // local, so it arrives once the tap is matched).
  bool heard = false;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!heard && std::chrono::steady_clock::now() < until) {
    tap.wait(std::chrono::milliseconds(50));
    tap.take([&](const viscera::client::TapSample& s) { heard = heard || s.stream == proto::Stream::scene_state; });
  }
  if (exercise.kind == viscera::training::ExerciseKind::palpation && !seed) seed = std::random_device{}() & 0xffffffffu;
  if (seed)
    std::printf("viscera-trainer: %s on scene %s, seed %llu\n", exercise.name.c_str(), exercise.scene.c_str(),
                static_cast<unsigned long long>(*seed));
  const auto outcome = client.load_scene(exercise.scene, std::chrono::seconds(60), seed);
  if (!outcome || !outcome->accepted) {
    std::fprintf(stderr, "viscera-trainer: the server did not load scene %s: %s\n", exercise.scene.c_str(),
                 outcome ? outcome->message.c_str() : "no answer in 60 s");
    return 3;
  }
  std::fflush(stdout);
  const auto feedback = [&] {
    for (const auto& line : scorer.take_feedback()) {
      std::printf("trainer: %s\n", line.c_str());
      std::fflush(stdout);
      client.annotate("trainer: " + line);  // for the console and the recording
    }
  };
  // The exercise's time limit, on this clock too (a trainee who stops sends nothing that would
  // carry the server's ticks past it), and a few seconds for the last forces to arrive.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(exercise.time_limit_s + 3.0);
  std::uint64_t newest = 0;
  auto newest_at = std::chrono::steady_clock::now();
  while (!g_stop && !scorer.ended() && std::chrono::steady_clock::now() < deadline) {
    tap.wait(std::chrono::milliseconds(20));
    tap.take([&](const viscera::client::TapSample& s) { scorer.take(s.stream, s.payload); });
    const auto now = std::chrono::steady_clock::now();
    if (scorer.newest_tick() != newest) {
      newest = scorer.newest_tick();
      newest_at = now;
    }
    // A margin behind the newest force; all of it once the instrument has been quiet a while.
    if (now - newest_at > kQuiet)
      scorer.advance(newest);
    else if (newest > kMarginTicks)
      scorer.advance(newest - kMarginTicks);
    feedback();
  }
  if (!scorer.ended()) {
    tap.take([&](const viscera::client::TapSample& s) { scorer.take(s.stream, s.payload); });
    if (g_stop)
      scorer.finish("the trainer was stopped (SIGINT or SIGTERM) before the exercise ended");
    else
      scorer.finish();
  }
  feedback();
  return conclude(scorer.report(), dir);
}

}  // namespace

int main(int argc, char** argv) {
  using viscera::common::UsageError;
  viscera::common::CommandLine cl(
      "viscera-trainer",
      "Training exercises with scores (docs/TRAINING.md).\n"
      "  run EXERCISE.json            loads the exercise's scene on the running server (a palpation's nodule placed by\n"
      "                               --seed, random when not given), follows the trainee's instrument, says what happens\n"
      "                               (on stdout and as annotations the console and the recording show), and scores the\n"
      "                               performance when it is complete or out of time\n"
      "  score EXERCISE.json FILE.mcap  the same score from a recording of the session (viscera-record)\n"
      "Exit status: 0 passed, 1 failed, 2 bad arguments or files (one line says why), 3 no server.");
  cl.usage("viscera-trainer run EXERCISE.json [--seed N] [--report-dir DIR] | score EXERCISE.json FILE.mcap [--report-dir DIR]");
  cl.flag("domain", "ID", "run: DDS domain", "0");
  cl.flag("station", "NAME", "run: the trainee station whose server to score: its DDS partition (viscera-server --station)", "");
  cl.flag("seed", "N", "run: the seed that places the scene's drawn regions (a palpation's hidden nodule)");
  cl.flag("client-id", "N", "run: this client's id (non-zero)", "800");
  cl.flag("report-dir", "DIR", "write the report here as EXERCISE.json and EXERCISE.md", "");
  cl.option_switch("replace", "replace the report's files if they exist (never through a symbolic link)");
  cl.allow_positional(3);
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto& args = cl.positional();
    if (args.empty() || !((args[0] == "run" && args.size() == 2) || (args[0] == "score" && args.size() == 3)))
      throw UsageError("expected: run EXERCISE.json | score EXERCISE.json FILE.mcap (see --help)");
    const Exercise exercise = viscera::training::read_exercise_file(args[1]);
    // Before the work: the folder made, and the report never replaces a file this run reads, nor
    // an earlier report unless asked.
    if (!cl.text("report-dir").empty()) {
      viscera::common::create_output_folder(cl.text("report-dir"), "--report-dir");
      for (const auto& f : report_files(cl.text("report-dir"), exercise.name)) {
        viscera::common::refuse_overwrite(f, {args.begin() + 1, args.end()}, "--report-dir");
        viscera::common::refuse_existing_output(f, cl.has("replace"), "--report-dir");
      }
    }
    if (args[0] == "score") {
      if (cl.has("seed")) throw UsageError("--seed is for run: a recording holds the place the nodule had");
      return score(exercise, args[2], cl.text("report-dir"));
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::optional<std::uint64_t> seed;
    if (cl.has("seed")) seed = cl.integer_in("seed", 0, 9007199254740991);
    return run(exercise, static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230)), viscera::protocol::checked_station(cl.text("station")), seed,
               static_cast<std::uint32_t>(cl.integer_in("client-id", 1, 4000000000)), cl.text("report-dir"));
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-trainer: %s\n", e.what());
    return 2;
  } catch (const viscera::common::InputError& e) {
    std::fprintf(stderr, "viscera-trainer: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-trainer: %s\n", e.what());
    return 3;
  }
}
