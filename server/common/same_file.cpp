#include "viscera/common/same_file.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <sys/stat.h>

#include "viscera/common/input_error.hpp"

namespace viscera::common {

bool same_file(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

void refuse_overwrite(const std::string& output, const std::vector<std::string>& inputs, const std::string& what) {
  for (const auto& input : inputs)
    if (same_file(output, input))
      throw InputError(output, 0, what, "is the same file as " + printable(input, 200) + ", which this program reads: write it elsewhere");
}

}  // namespace viscera::common
