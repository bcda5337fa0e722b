#include "say.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cstdarg>
#include <cstdio>
#include <memory>

#include "viscera/common/program_log.hpp"

namespace viscera::haptic {

namespace {
std::shared_ptr<spdlog::logger> g_lines;
}

void say(const char* format, ...) {
  char line[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  if (g_lines) {
    g_lines->info("{}", line);
  } else {
    std::printf("%s\n", line);
    std::fflush(stdout);
  }
}

void start_saying() { g_lines = common::background_lines("haptic-client"); }

void stop_saying() { g_lines.reset(); }

}  // namespace viscera::haptic
