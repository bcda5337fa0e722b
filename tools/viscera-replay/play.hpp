#pragma once  // SPDX-License-Identifier: Apache-2.0
// viscera-replay play: a recording published again onto a DDS partition of its own at its
// original pace times a rate, so consoles and other clients see the session again; paused,
// resumed and sought from the terminal or by session requests sent to the replayer.
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

namespace viscera::replay {

struct PlayOptions {
  std::string recording;
  double rate = 1.0;
  bool loop = false;
  double from_s = 0;  ///< from the recording's start
  std::optional<double> to_s;  ///< default: its end
  std::string partition = "viscera-replay";
  std::optional<std::uint32_t> domain;  ///< default: the recording's
  std::uint32_t client_id = 950;  ///< the replayer's id in the outcomes it publishes
  double discovery_s = 1.0;  ///< waits this long for the partition's clients to be discovered
  bool keys = true;  ///< read keys when the standard input is a terminal
  bool quiet = false;
};

/// Plays until the end (or forever with loop) or until `stop`; returns 0.
int play(const PlayOptions& options, const std::atomic<bool>& stop);

}  // namespace viscera::replay
