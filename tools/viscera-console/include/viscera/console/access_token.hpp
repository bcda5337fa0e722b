#pragma once  // SPDX-License-Identifier: Apache-2.0
// The console's access token: read from a file given at start, compared in constant time.
#include <string>
#include <string_view>
#include <vector>

namespace viscera::console {

/// The shortest token accepted [characters]: 128 bits as hex.
inline constexpr std::size_t kMinTokenChars = 32;
/// The longest [characters]: it travels in every address and every request.
inline constexpr std::size_t kMaxTokenChars = 256;

/// Reads the token from `path`, a regular file of at most 4 KiB (never a FIFO or a device): its
/// first line, trimmed of surrounding blanks; printable ASCII without spaces, kMinTokenChars to
/// kMaxTokenChars. Throws common::InputError naming the file otherwise.
std::string read_token_file(const std::string& path);
/// A warning when others than the file's owner may read a secret's file, the token's or the TLS
/// key's (empty otherwise); `risk` says what a reader could do.
std::string token_file_warning(const std::string& path, std::string_view risk = "anyone who reads it commands the session");

/// Whether a WebSocket upgrade with this Origin header may open: none (not a browser: the token
/// still decides), the console's own address (`host`, the request's Host header, as http:// or
/// https://), or one of `allowed` (a proxy's address, a Foxglove web app), exactly. A page of
/// another site that learnt the token cannot open a session from the user's browser.
bool origin_allowed(std::string_view origin, std::string_view host, const std::vector<std::string>& allowed);

/// Whether `given` equals `token`, in time that depends on the token's length only (never on
/// where the two first differ).
bool token_matches(std::string_view given, std::string_view token);

}  // namespace viscera::console
