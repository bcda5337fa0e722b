#pragma once
// Whole files as bytes, for what is stored or sent verbatim (the files a scene was built from, in
// recordings). Errors are InputErrors naming the file.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace viscera::common {

/// The content of a regular file; throws InputError if it cannot be read or is larger than
/// `max_bytes`.
std::vector<std::uint8_t> read_file_bytes(const std::string& path, std::uint64_t max_bytes = std::uint64_t{1} << 30);
/// Writes (replaces) a file; throws InputError if it cannot.
void write_file_bytes(const std::string& path, std::span<const std::uint8_t> bytes);

}  // namespace viscera::common
