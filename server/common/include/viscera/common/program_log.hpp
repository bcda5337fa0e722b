#pragma once  // SPDX-License-Identifier: Apache-2.0
// A program's log, for the long-running programs (the server, the recorder, the console): spdlog
// lines with the time, the level and the program's name,
//   2026-11-26 17:20:01.123 info viscera-server: scene liver: 1,493 tets ...
// on standard output, warnings and errors on standard error (one line each), flushed at every
// line so that a supervisor or a test sees it at once; with a file, the same lines are appended
// to it as well (a service's log that outlives the terminal). Command-line errors are printed
// before the log exists, plain, as every program prints them.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/logger.h>

namespace viscera::common {

/// Who writes the lines out: the thread that logs (in_line), or a thread of the log's own
/// (background; at normal, not real-time, priority) that takes them from a queue of up to
/// kQueuedLogLines, so that a real-time thread that logs never waits for a slow disk or a full
/// pipe. When the queue is full the oldest queued line is dropped (log_lines_dropped() counts them);
/// the lines still queued are written when the last reference to the log is released.
enum class LogDelivery { in_line, background };
inline constexpr std::size_t kQueuedLogLines = 8192;

/// `file`: "" for none; refused (InputError) if it is one of `inputs`, the files the program
/// reads (no program writes over a file it reads), or cannot be opened for appending. One
/// background log per process.
std::shared_ptr<spdlog::logger> program_log(const std::string& program, const std::string& file = {}, const std::vector<std::string>& inputs = {},
                                            LogDelivery delivery = LogDelivery::in_line);
/// Plain lines (no time, no level) for a program's real-time loop: information on standard
/// output, warnings and errors on standard error, written as LogDelivery::background writes them.
std::shared_ptr<spdlog::logger> background_lines(const std::string& program);
/// Lines the background log dropped because its queue was full (0 without one).
std::size_t log_lines_dropped();

}  // namespace viscera::common
