#include "viscera/console/access_token.hpp"

#include <fstream>

#include "viscera/common/input_error.hpp"

namespace viscera::console {

std::string read_token_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw common::InputError(path, 0, "--token-file", "cannot be read");
  std::string line;
  std::getline(in, line);
  const auto first = line.find_first_not_of(" \t\r");
  const auto last = line.find_last_not_of(" \t\r");
  std::string token = first == std::string::npos ? std::string() : line.substr(first, last - first + 1);
  for (const char c : token)
    if (c <= ' ' || c > '~') throw common::InputError(path, 1, "token", "holds a blank or a character outside printable ASCII");
  if (token.size() < kMinTokenChars)
    throw common::InputError(
        path, 1, "token",
        "has " + std::to_string(token.size()) + " characters (at least " + std::to_string(kMinTokenChars) + "; e.g. openssl rand -hex 16)");
  return token;
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
