#pragma once  // SPDX-License-Identifier: Apache-2.0
// Figures into the lab's sentences: printf's format with up to three numbers.
#include <cstdio>
#include <string>

namespace viscera::lab {

inline std::string format_figures(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, a, b, c);  // NOLINT(clang-diagnostic-format-nonliteral): the lab's own literals
  return buffer;
}

}  // namespace viscera::lab
