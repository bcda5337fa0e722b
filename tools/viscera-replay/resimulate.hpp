#pragma once  // SPDX-License-Identifier: Apache-2.0
// viscera-replay resimulate: a fresh lockstep server on the recorded scene, fed the recorded
// commands and requests at the ticks the original applied them, every force, event and frame
// compared (client-sdk/recording: lockstep_plan.hpp, resimulation_check.hpp).
#include <atomic>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace viscera::replay {

struct ResimulateOptions {
  std::string recording;
  std::optional<std::string> scene;  ///< a scene file in place of the recorded one (what-if)
  std::optional<std::string> report;  ///< JSON report
  bool replace_report = false;  ///< replace an existing report (--replace); else refused
  std::string server;  ///< viscera-server program
  std::optional<std::uint32_t> domain;  ///< default: the recording's
  int window = 64;  ///< steps in flight
  double server_timeout_s = 120;  ///< for the server to build the organ and join
  bool quiet = false;
};

/// Returns 0 bit-identical, 1 diverged; throws common::InputError (bad recording or scene),
/// std::runtime_error (the server could not be run), Interrupted once `stop` is set (SIGINT,
/// SIGTERM: the lockstep server is stopped and the temporary folder removed on the way out).
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted: the re-simulation was stopped") {}
};
int resimulate(const ResimulateOptions& options, const std::atomic<bool>& stop);

}  // namespace viscera::replay
