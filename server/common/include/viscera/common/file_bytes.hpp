#pragma once  // SPDX-License-Identifier: Apache-2.0
// Whole files as bytes, for what is stored or sent verbatim (the files a scene was built from, in
// recordings). Errors are InputErrors naming the file.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::common {

/// The content of a regular file; throws InputError if it cannot be read or is larger than
/// `max_bytes`.
std::vector<std::uint8_t> read_file_bytes(const std::string& path, std::uint64_t max_bytes = std::uint64_t{1} << 30);
/// Writes (replaces) a regular file: the one way every program writes an output (a report, an SVG,
/// a CSV, a material, a mesh frame). A symbolic link at the path is never written through (a link
/// planted in a shared folder would have the output written over its target, as root over
/// /etc/passwd), and a FIFO, a device or a folder is refused instead of blocking or being written
/// into. Throws InputError naming the file.
void write_file_bytes(const std::string& path, std::span<const std::uint8_t> bytes);
void write_file_text(const std::string& path, std::string_view text);
/// Creates the folder `dir` (and its parents) for outputs, or throws InputError naming it and
/// `what` (the flag: "--out") with the reason: a file in the way, a name too long, no permission.
/// Called before the work, so a long run never fails at its end for want of a folder.
void create_output_folder(const std::string& dir, const std::string& what);

}  // namespace viscera::common
