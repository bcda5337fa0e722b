#pragma once
// Configuration files are strict: a misspelt or misplaced field would otherwise be ignored and
// its default used without a word.
#include <algorithm>
#include <initializer_list>
#include <string>

#include "common/input_error.hpp"

namespace viscera::tissue {

/// Throws InputError(source, prefix + key, "unknown field (known here: ...)") for the first key of
/// the JSON object `o` (nlohmann::json) that is not in `known`.
template <class Json>
void require_known_fields(const Json& o, const std::string& source, const std::string& prefix, std::initializer_list<const char*> known) {
  for (const auto& item : o.items()) {
    const std::string& key = item.key();
    if (std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) continue;
    std::string list;
    for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
    throw InputError(source, 0, prefix + key, "unknown field (known here: " + list + ")");
  }
}

}  // namespace viscera::tissue
