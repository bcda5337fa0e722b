// CRC-32 and the chunk compressions MCAP names, against the standard check value, the bitwise  // SPDX-License-Identifier: Apache-2.0
// definition and each other: zstd and lz4 round trips, wrong and forged sizes refused at no cost.
#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/mcap/byte_codec.hpp"
#include "viscera/mcap/compression.hpp"
#include "viscera/mcap/integrity.hpp"

#include "payload.hpp"

namespace {

using namespace viscera::mcap;
using viscera::mcap::test::payload;

TEST(Crc32, MatchesTheStandardCheckValue) {
  // CRC-32/ISO-HDLC (zlib's, MCAP's) of "123456789" is 0xCBF43926 (the catalogue's check value).
  const std::string s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()), 0xCBF43926u);
  // Updating in pieces gives the same.
  std::uint32_t c = crc32_update(kCrc32Init, reinterpret_cast<const std::uint8_t*>(s.data()), 4);
  c = crc32_update(c, reinterpret_cast<const std::uint8_t*>(s.data()) + 4, 5);
  EXPECT_EQ(crc32_final(c), 0xCBF43926u);
}

TEST(Crc32, EightBytesAtATimeEqualsTheBitwiseDefinition) {
  // The polynomial division bit by bit (the definition, no tables), against the sliced tables
  // on every length up to 70 and every split point of the data into two updates.
  const auto bitwise = [](const std::vector<std::uint8_t>& d) {
    std::uint32_t crc = 0xFFFFFFFFu;
    for (std::uint8_t b : d) {
      crc ^= b;
      for (int k = 0; k < 8; ++k) crc = (crc & 1u) ? 0xEDB88320u ^ (crc >> 1) : crc >> 1;
    }
    return ~crc;
  };
  std::vector<std::uint8_t> data;
  std::uint32_t x = 12345;
  for (std::size_t n = 0; n <= 70; ++n) {
    for (std::size_t split = 0; split <= n; ++split) {
      std::uint32_t c = crc32_update(kCrc32Init, data.data(), split);
      c = crc32_update(c, data.data() + split, n - split);
      ASSERT_EQ(crc32_final(c), bitwise(data)) << n << " bytes split at " << split;
    }
    x = x * 1664525u + 1013904223u;
    data.push_back(static_cast<std::uint8_t>(x >> 24));
  }
}

TEST(Compression, ZstdAndLz4RoundTripAndRefuseAWrongSize) {
  const auto data = payload(3, 9, 100000);
  for (const std::string c : {"zstd", "lz4", ""}) {
    const auto packed = compress(c, data);
    EXPECT_EQ(decompress(c, packed, data.size()), data) << c;
    EXPECT_THROW(decompress(c, packed, data.size() + 1), FormatError) << c;
    EXPECT_THROW(decompress(c, packed, data.size() - 1), FormatError) << c;
  }
  EXPECT_THROW(compress("gzip", data), std::invalid_argument);
}

TEST(Compression, AForgedSizeCostsNoMemoryAndIsNamed) {
  // A chunk whose header claims 1 GiB but holds 100 kB: refused with both sizes, at once (the
  // output grows with what decompresses; the fuzzer found the 4 GiB allocation this replaced).
  const auto data = payload(4, 9, 100000);
  for (const std::string c : {"zstd", "lz4"}) {
    const auto packed = compress(c, data);
    const auto t0 = std::chrono::steady_clock::now();
    try {
      (void)decompress(c, packed, kMaxChunkBytes);
      ADD_FAILURE() << c << ": accepted";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("decompressed to 100000 bytes, its header says 1073741824"), std::string::npos) << e.what();
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0) << c;
    EXPECT_THROW(decompress(c, packed, kMaxChunkBytes + 1), FormatError) << c;
    // Cut short: the frame is incomplete.
    EXPECT_THROW(decompress(c, std::span(packed).first(packed.size() / 2), data.size()), FormatError) << c;
  }
}

}  // namespace
