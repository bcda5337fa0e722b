#include "resimulate.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <unistd.h>

#include "viscera/client/lockstep_driver.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/process/child_process.hpp"
#include "viscera/recording/lockstep_plan.hpp"
#include "viscera/recording/recording.hpp"
#include "viscera/recording/resimulation_check.hpp"
#include "viscera/recording/scene_extraction.hpp"

namespace viscera::replay {

namespace fs = std::filesystem;
namespace proto = viscera::protocol;
namespace rec = viscera::recording;

namespace {

/// A directory removed with everything in it when done. One left by a run that was killed
/// (SIGKILL runs no destructor) is removed by the next run, once the process that made it is gone.
struct TempDir {
  fs::path path;
  TempDir() {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path(), ec)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("viscera-resim-", 0) != 0) continue;
      const long pid = std::strtol(name.c_str() + 14, nullptr, 10);
      if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(e.path(), ec);
    }
    path = fs::temp_directory_path() / ("viscera-resim-" + std::to_string(::getpid()) + "-" + std::to_string(proto::now_ns()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

using ull = unsigned long long;

void print_plan(const ResimulateOptions& o, const rec::LockstepPlan& plan, const rec::ExtractedScenes& scenes) {
  const std::uint64_t ticks = plan.last_tick - plan.first_tick + 1;
  std::printf("viscera-replay: re-simulating %s: ticks %llu to %llu (%llu), %llu forces, %llu events, %llu frames recorded\n", o.recording.c_str(),
              ull(plan.first_tick), ull(plan.last_tick), ull(ticks), ull(plan.recorded_forces), ull(plan.recorded_events), ull(plan.recorded_frames));
  std::printf("viscera-replay: recorded by %s\n", plan.scene.server_version.c_str());
  for (const auto& d : scenes.differences) std::printf("viscera-replay: what-if: %s\n", d.c_str());
  for (const auto& n : plan.notes) std::printf("viscera-replay: note: %s\n", n.c_str());
  std::fflush(stdout);
}

/// The lockstep server in a process of its own, driven step by step; its log's tail in every
/// failure.
class LockstepRun {
 public:
  LockstepRun(const ResimulateOptions& o, const rec::ExtractedScenes& scenes, std::uint32_t domain, const std::string& partition, const fs::path& log,
              const std::atomic<bool>& stop)
      : o_(o),
        stop_(stop),
        driver_(domain, partition),
        // On the driver's domain, whatever the recorded scene file says (--domain).
        server_({o.server, "--lockstep", "--scene", scenes.first_scene, "--scene-dir", scenes.scene_dir, "--station", partition, "--domain",
                 std::to_string(domain), "--quiet"},
                log.string()) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.server_timeout_s);
    while (!driver_.wait_for_server(std::chrono::milliseconds(200))) {
      if (stop_) throw Interrupted();
      if (!server_.alive()) fail("the lockstep server (" + o.server + ") stopped before it was ready");
      if (std::chrono::steady_clock::now() > end)
        fail("no lockstep server ready within " + std::to_string(static_cast<int>(o.server_timeout_s)) + " s");
    }
  }

  /// Every step of the plan, a window of them in flight, each result checked in order; the
  /// seconds it took.
  double run(const rec::LockstepPlan& plan, rec::ResimulationCheck& check) {
    std::uint64_t next_send = plan.first_tick, next_result = plan.first_tick;
    const auto start = std::chrono::steady_clock::now();
    auto last_status = start;
    while (next_result <= plan.last_tick) {
      for (; next_send <= plan.last_tick && next_send < next_result + static_cast<std::uint64_t>(o_.window); ++next_send) {
        proto::LockstepStep step = plan.step(next_send);
        if (next_send == plan.first_tick) step.sim_time_s = plan.sim_time_s;
        driver_.send(step);
      }
      std::optional<proto::LockstepResult> result;
      for (int waited = 0; !result && waited < 150 && !stop_; ++waited) result = driver_.next_result(std::chrono::milliseconds(200));
      if (stop_) throw Interrupted();
      if (!result) {
        if (!server_.alive()) fail("the lockstep server stopped at tick " + std::to_string(next_result));
        fail("no result for tick " + std::to_string(next_result) + " within 30 s");
      }
      if (result->tick != next_result)
        fail("result for tick " + std::to_string(result->tick) + " where tick " + std::to_string(next_result) + " was due" +
             (result->error.empty() ? "" : " (" + result->error + ")"));
      check.check(*result);
      ++next_result;
      const auto now = std::chrono::steady_clock::now();
      if (!o_.quiet && now - last_status >= std::chrono::seconds(1)) {
        last_status = now;
        const auto ticks = static_cast<double>(plan.last_tick - plan.first_tick + 1);
        const double done = static_cast<double>(next_result - plan.first_tick) / ticks;
        const double elapsed = std::chrono::duration<double>(now - start).count();
        std::printf("viscera-replay: tick %llu of %llu (%.0f%%), %.0f s left; %llu forces identical%s\n", ull(next_result - plan.first_tick),
                    ull(plan.last_tick - plan.first_tick + 1), 100 * done, done > 0 ? elapsed * (1 - done) / done : 0.0,
                    ull(check.counts().forces_identical), check.first_divergence() ? ", diverged" : "");
        std::fflush(stdout);
      }
    }
    server_.stop();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    const std::string tail = server_.log_tail();
    throw std::runtime_error(what + (tail.empty() ? "" : "; the lockstep server said:\n" + tail));
  }

  const ResimulateOptions& o_;
  const std::atomic<bool>& stop_;
  client::LockstepDriver driver_;
  process::ChildProcess server_;
};

/// The outcome in one line; 0 when bit-identical, else 1.
int print_outcome(const rec::ResimulationCheck& check, const rec::LockstepPlan& plan) {
  const auto& c = check.counts();
  if (check.identical()) {
    std::printf(
        "viscera-replay: bit-identical: %llu ticks, %llu forces, %llu events, %llu frames (%llu forces' stiffness differs: the live server's "
        "compliance timing)\n",
        ull(c.ticks), ull(c.forces_identical), ull(c.events_identical), ull(c.frames_identical), ull(c.stiffness_differences));
    return 0;
  }
  if (const auto& d = check.first_divergence())
    std::printf("viscera-replay: diverged: first at tick %llu, %s, %s: %s recorded %s, recomputed %s\n", ull(d->tick), d->topic.c_str(),
                d->what.c_str(), d->field.c_str(), d->recorded.c_str(), d->recomputed.c_str());
  else
    std::printf("viscera-replay: not identical: %llu of %llu forces, %llu of %llu events, %llu of %llu frames reproduced\n", ull(c.forces_identical),
                ull(plan.recorded_forces), ull(c.events_identical), ull(plan.recorded_events), ull(c.frames_identical), ull(plan.recorded_frames));
  return 1;
}

}  // namespace

int resimulate(const ResimulateOptions& o, const std::atomic<bool>& stop) {
  if (o.report) {  // before the work: never over a file this run reads
    std::vector<std::string> inputs{o.recording};
    if (o.scene) inputs.push_back(*o.scene);
    common::refuse_overwrite(*o.report, inputs, "--report");
    common::refuse_existing_output(*o.report, o.replace_report, "--report");
  }
  rec::Recording recording(o.recording);
  const rec::LockstepPlan plan = rec::make_lockstep_plan(recording);
  TempDir dir;
  const rec::ExtractedScenes scenes = rec::extract_scenes(recording, dir.path.string(), o.scene);
  const std::uint32_t domain = o.domain ? *o.domain : recording.domain_id();
  const std::string partition = "viscera-resimulate-" + std::to_string(::getpid()) + "-" + std::to_string(proto::now_ns() % 1000000000);
  if (!o.quiet) print_plan(o, plan, scenes);

  rec::ResimulationCheck check(plan, recording);
  const double seconds = LockstepRun(o, scenes, domain, partition, dir.path / "server.log", stop).run(plan, check);

  nlohmann::json report = check.report();
  report["recording"] = o.recording;
  report["recorded_by"] = plan.scene.server_version;
  report["scene"] = o.scene ? *o.scene : plan.scene.file("scene") ? plan.scene.file("scene")->path : "";
  report["what_if"] = scenes.differences;
  report["seconds"] = seconds;
  if (o.report) {
    common::write_file_text(*o.report, report.dump(2) + "\n");
  }
  return print_outcome(check, plan);
}

}  // namespace viscera::replay
