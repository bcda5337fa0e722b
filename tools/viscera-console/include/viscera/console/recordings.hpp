#pragma once  // SPDX-License-Identifier: Apache-2.0
// The session recordings a browser may open for replay: files of one folder, named plainly (no
// path can be given, so a browser cannot make the bridge read an arbitrary file).
#include <string>
#include <vector>

namespace viscera::console {

/// [A-Za-z0-9._-], 1 to 128 characters, not starting with '.', ending in ".mcap".
bool is_recording_name(const std::string& name);
/// The regular files in `dir` with such names, sorted; none if `dir` is empty or unreadable.
std::vector<std::string> list_recordings(const std::string& dir);

}  // namespace viscera::console
