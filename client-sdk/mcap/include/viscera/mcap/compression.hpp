#pragma once  // SPDX-License-Identifier: Apache-2.0
// Chunk compression as MCAP names it: "zstd" (Zstandard frame, Debian's libzstd), "lz4" (LZ4
// frame, Debian's liblz4) or "" (none).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace viscera::mcap {

/// Throws std::invalid_argument for another name.
std::vector<std::uint8_t> compress(const std::string& compression, std::span<const std::uint8_t> data);
/// A chunk larger than this, uncompressed, is taken for damage (the recorder closes its chunks at
/// 4 MiB; other writers' defaults are smaller still).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;
/// Throws FormatError if the data do not decompress to exactly `uncompressed_size` bytes (memory
/// grows with what actually decompresses, never with what a header claims).
std::vector<std::uint8_t> decompress(const std::string& compression, std::span<const std::uint8_t> data, std::uint64_t uncompressed_size);

}  // namespace viscera::mcap
