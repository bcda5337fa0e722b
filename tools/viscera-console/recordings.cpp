#include "viscera/console/recordings.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace viscera::console {

bool is_recording_name(const std::string& n) {
  const std::string ext = ".mcap";
  return n.size() > ext.size() && n.size() <= 128 && n[0] != '.' && n.compare(n.size() - ext.size(), ext.size(), ext) == 0 &&
         std::all_of(n.begin(), n.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-'; });
}

std::vector<std::string> list_recordings(const std::string& dir) {
  std::vector<std::string> out;
  if (dir.empty()) return out;
  std::error_code ec;
  const auto folder = std::filesystem::canonical(dir, ec);
  if (ec) return out;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    if (!e.is_regular_file(ec) || !is_recording_name(name)) continue;
    // A symbolic link counts only if it stays inside the folder (never /etc/passwd).
    const auto target = std::filesystem::canonical(e.path(), ec);
    if (ec || target.parent_path() != folder) continue;
    out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace viscera::console
