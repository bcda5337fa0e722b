#include <array>  // SPDX-License-Identifier: Apache-2.0

#include "viscera/mcap/mcap_format.hpp"

namespace viscera::mcap {

namespace {

// Slicing by 8 (Intel's method): eight tables, table k giving the CRC of a byte followed by k zero
// bytes, so that eight bytes are folded in per step with eight independent lookups instead of
// eight dependent ones. A recording's chunks are checked whole: the byte-at-a-time loop took half
// of the time to read a 10-minute session.
using Tables = std::array<std::array<std::uint32_t, 256>, 8>;

constexpr Tables make_tables() {
  Tables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < 8; ++k)
    for (std::size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
  return t;
}
constexpr Tables kTables = make_tables();

constexpr std::uint32_t little_endian_32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}

}  // namespace

std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
  const auto& t = kTables;
  for (; size >= 8; data += 8, size -= 8) {
    const std::uint32_t one = little_endian_32(data) ^ crc, two = little_endian_32(data + 4);
    crc = t[7][one & 0xFFu] ^ t[6][(one >> 8) & 0xFFu] ^ t[5][(one >> 16) & 0xFFu] ^ t[4][one >> 24] ^ t[3][two & 0xFFu] ^ t[2][(two >> 8) & 0xFFu] ^
          t[1][(two >> 16) & 0xFFu] ^ t[0][two >> 24];
  }
  for (; size > 0; ++data, --size) crc = t[0][(crc ^ *data) & 0xFFu] ^ (crc >> 8);
  return crc;
}

}  // namespace viscera::mcap
