#include "viscera/lab/test_history.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>

#include "viscera/lab/command_path.hpp"

namespace viscera::lab {

void carry_history(Dataset& d) {
  double tension = 0.0, compression = 0.0;  // what the data set's specimen went through so far
  for (TestData& t : d.tests) {
    const bool shared = d.history == History::carried && !t.specimen;
    t.before_tension = shared ? tension : 0.0;
    t.before_compression = shared ? compression : 0.0;
    if (!shared) continue;
    const std::vector<double>& path = t.control == Control::strain ? command_path(t.time_s, t.strain).value : t.strain;
    for (const double e : path) {
      tension = std::max(tension, e);
      compression = std::max(compression, -e);
    }
  }
}

TestData untouched(TestData t) {
  t.before_tension = t.before_compression = 0.0;
  return t;
}

}  // namespace viscera::lab
