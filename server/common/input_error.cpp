#include "viscera/common/input_error.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cstdio>

namespace viscera::common {

namespace {
std::string compose(const std::string& source, long line, const std::string& field, const std::string& message) {
  std::string s = source;
  if (line > 0) s += ":" + std::to_string(line);
  if (!field.empty()) s += ": " + field;
  return s + ": " + message;
}
}  // namespace

InputError::InputError(std::string source, long line, std::string field, const std::string& message)
    : std::runtime_error(compose(source, line, field, message)), source_(std::move(source)), line_(line), field_(std::move(field)) {}

std::string short_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string exact_number(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

std::string printable(std::string_view text, std::size_t max_chars) {
  std::string out;
  for (const char c : text) {
    if (out.size() >= max_chars) return out + "...";
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", u);
      out += b;
    }
  }
  return out;
}

}  // namespace viscera::common
