#pragma once  // SPDX-License-Identifier: Apache-2.0
// Names that become parts of paths (scene names, exercise names): letters, digits, '.', '_' and
// '-', 1 to 64 of them, not starting with '.'. No separator, no "..", no NUL, nothing a terminal
// would act on. And text that is printed: no control characters.
#include <algorithm>
#include <cctype>
#include <string_view>

namespace viscera::common {

inline bool is_plain_name(std::string_view name) {
  return !name.empty() && name.size() <= 64 && name[0] != '.' && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

/// Whether text holds a byte a terminal acts on: a C0 control (a newline, an escape), DEL, or a C1
/// control in UTF-8 (U+0080 to U+009F). Text read from files that programs print must not.
inline bool has_control_characters(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) return true;
    if (c == 0xc2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) >= 0x80 && static_cast<unsigned char>(text[i + 1]) <= 0x9f)
      return true;
  }
  return false;
}

/// The rule, in the words every message uses.
inline constexpr const char* kPlainNameRule = "letters, digits, '.', '_', '-'; 1 to 64 of them, not starting with '.'; no path";

}  // namespace viscera::common
