#pragma once
// Names that become parts of paths (scene names, exercise names): letters, digits, '.', '_' and
// '-', 1 to 64 of them, not starting with '.'. No separator, no "..", no NUL, nothing a terminal
// would act on.
#include <algorithm>
#include <cctype>
#include <string_view>

namespace viscera::common {

inline bool is_plain_name(std::string_view name) {
  return !name.empty() && name.size() <= 64 && name[0] != '.' && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

/// The rule, in the words every message uses.
inline constexpr const char* kPlainNameRule = "letters, digits, '.', '_', '-'; 1 to 64 of them, not starting with '.'; no path";

}  // namespace viscera::common
