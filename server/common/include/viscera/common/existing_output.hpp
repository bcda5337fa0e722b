#pragma once  // SPDX-License-Identifier: Apache-2.0
// An output that exists already is replaced only when the user asked for it (`--replace`, as for
// recordings); otherwise the program stops before its work with one line naming the file and the
// flag. Checked before the work, so a long run never ends in a refusal.
#include <string>

namespace viscera::common {

/// Throws InputError naming `path` and `flag` if something is at `path` (a file, a link, a folder)
/// and `replace` is false.
void refuse_existing_output(const std::string& path, bool replace, const std::string& flag);
/// A folder of outputs: throws InputError naming `dir` and `flag` if it holds anything or is a link
/// and `replace` is false (an empty folder, or none, is written into).
void refuse_existing_folder(const std::string& dir, bool replace, const std::string& flag);

}  // namespace viscera::common
