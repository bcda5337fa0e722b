#pragma once  // SPDX-License-Identifier: Apache-2.0
// What the MCAP tests share: a payload whose every byte depends on its channel, its index and its
// position, so that a message read back in the wrong place or order differs.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace viscera::mcap::test {

inline std::vector<std::uint8_t> payload(int channel, int k, std::size_t size) {
  std::vector<std::uint8_t> p(size);
  for (std::size_t i = 0; i < size; ++i) p[i] = static_cast<std::uint8_t>(channel * 31 + k * 7 + static_cast<int>(i) * 13);
  return p;
}

}  // namespace viscera::mcap::test
