#pragma once
// A program's log, for the long-running programs (the server, the recorder, the console): spdlog
// lines with the time, the level and the program's name,
//   2026-11-26 17:20:01.123 info viscera-server: scene liver: 1,493 tets ...
// on standard output, warnings and errors on standard error (one line each), flushed at every
// line so that a supervisor or a test sees it at once; with a file, the same lines are appended
// to it as well (a service's log that outlives the terminal). Command-line errors are printed
// before the log exists, plain, as every program prints them.
#include <memory>
#include <string>
#include <vector>

#include <spdlog/logger.h>

namespace viscera::common {

/// `file`: "" for none; refused (InputError) if it is one of `inputs`, the files the program
/// reads (no program writes over a file it reads), or cannot be opened for appending.
std::shared_ptr<spdlog::logger> program_log(const std::string& program, const std::string& file = {}, const std::vector<std::string>& inputs = {});

}  // namespace viscera::common
