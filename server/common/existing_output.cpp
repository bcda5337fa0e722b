#include "viscera/common/existing_output.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <filesystem>
#include <system_error>

#include "viscera/common/input_error.hpp"

namespace viscera::common {

void refuse_existing_output(const std::string& path, bool replace, const std::string& flag) {
  std::error_code ec;
  if (replace || !std::filesystem::exists(std::filesystem::symlink_status(path, ec))) return;
  throw InputError(path, 0, flag, "exists already: pass --replace to replace it, or name another path");
}

void refuse_existing_folder(const std::string& dir, bool replace, const std::string& flag) {
  std::error_code ec;
  const auto status = std::filesystem::symlink_status(dir, ec);
  if (replace || !std::filesystem::exists(status)) return;
  if (std::filesystem::is_directory(status) && std::filesystem::directory_iterator(dir, ec) == std::filesystem::directory_iterator()) return;
  if (std::filesystem::is_symlink(status))
    throw InputError(dir, 0, flag, "is a symbolic link: pass --replace to write into the folder it names, or name a new folder");
  throw InputError(dir, 0, flag, "holds files already: pass --replace to write into it (files of the same names are replaced), or name a new folder");
}

}  // namespace viscera::common
