#pragma once
// The console's access token: read from a file given at start, compared in constant time.
#include <string>
#include <string_view>

namespace viscera::console {

/// The shortest token accepted [characters]: 128 bits as hex.
inline constexpr std::size_t kMinTokenChars = 32;
/// The longest [characters]: it travels in every address and every request.
inline constexpr std::size_t kMaxTokenChars = 256;

/// Reads the token from `path`, a regular file of at most 4 KiB (never a FIFO or a device): its
/// first line, trimmed of surrounding blanks; printable ASCII without spaces, kMinTokenChars to
/// kMaxTokenChars. Throws common::InputError naming the file otherwise.
std::string read_token_file(const std::string& path);
/// A warning when others than the file's owner may read the token file (empty otherwise).
std::string token_file_warning(const std::string& path);

/// Whether `given` equals `token`, in time that depends on the token's length only (never on
/// where the two first differ).
bool token_matches(std::string_view given, std::string_view token);

}  // namespace viscera::console
