#pragma once  // SPDX-License-Identifier: Apache-2.0
// No program writes over a file it reads: an output is compared with the inputs by device and
// inode, so a hard link, a symbolic link or another spelling of an input's path is caught too.
#include <string>
#include <vector>

namespace viscera::common {

/// Whether both paths exist and name the same file (device and inode, links followed).
bool same_file(const std::string& a, const std::string& b);
/// Throws InputError naming `output` if it is one of `inputs` (same_file). `what` says what the
/// output is ("the report", "--out").
void refuse_overwrite(const std::string& output, const std::vector<std::string>& inputs, const std::string& what);

}  // namespace viscera::common
