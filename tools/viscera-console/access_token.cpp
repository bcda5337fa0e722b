#include "viscera/console/access_token.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cstdio>

#include <sys/stat.h>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"

namespace viscera::console {

std::string read_token_file(const std::string& path) {
  const std::string text = common::read_text_file(path, 4096);
  const std::string line = text.substr(0, text.find('\n'));
  const auto first = line.find_first_not_of(" \t\r");
  const auto last = line.find_last_not_of(" \t\r");
  std::string token = first == std::string::npos ? std::string() : line.substr(first, last - first + 1);
  for (const char c : token)
    if (c <= ' ' || c > '~') throw common::InputError(path, 1, "token", "holds a blank or a character outside printable ASCII");
  if (token.size() < kMinTokenChars || token.size() > kMaxTokenChars)
    throw common::InputError(path, 1, "token",
                             "has " + std::to_string(token.size()) + " characters (" + std::to_string(kMinTokenChars) + " to " +
                                 std::to_string(kMaxTokenChars) + "; e.g. openssl rand -hex 16)");
  return token;
}

std::string token_file_warning(const std::string& path, std::string_view risk) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || (st.st_mode & (S_IRWXG | S_IRWXO)) == 0) return {};
  char mode[8];
  std::snprintf(mode, sizeof mode, "%03o", static_cast<unsigned>(st.st_mode & 0777));
  return common::printable(path, 200) + " (mode " + mode + ") may be read by others than its owner: " + std::string(risk) + " (chmod 600 " +
         common::printable(path, 200) + ")";
}

bool origin_allowed(std::string_view origin, std::string_view host, const std::vector<std::string>& allowed) {
  if (origin.empty()) return true;
  if (!host.empty() && (origin == "http://" + std::string(host) || origin == "https://" + std::string(host))) return true;
  return std::find(allowed.begin(), allowed.end(), origin) != allowed.end();
}

bool token_matches(std::string_view given, std::string_view token) {
  // Every character of the token is compared whatever the given one holds; a length mismatch is
  // folded into the same accumulator.
  unsigned diff = given.size() == token.size() ? 0U : 1U;
  for (std::size_t i = 0; i < token.size(); ++i) {
    const unsigned char g = i < given.size() ? static_cast<unsigned char>(given[i]) : 0U;
    diff |= g ^ static_cast<unsigned char>(token[i]);
  }
  return diff == 0;
}

}  // namespace viscera::console
