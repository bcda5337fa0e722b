#pragma once
// Chunk compression as MCAP names it: "zstd" (Zstandard frame, Debian's libzstd), "lz4" (LZ4
// frame, Debian's liblz4) or "" (none).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace viscera::mcap {

/// Throws std::invalid_argument for another name.
std::vector<std::uint8_t> compress(const std::string& compression, std::span<const std::uint8_t> data);
/// Throws FormatError if the data do not decompress to exactly `uncompressed_size` bytes.
std::vector<std::uint8_t> decompress(const std::string& compression, std::span<const std::uint8_t> data, std::uint64_t uncompressed_size);

}  // namespace viscera::mcap
