#pragma once  // SPDX-License-Identifier: Apache-2.0
// The one check every received payload passes before it is read: the FlatBuffers verifier, with
// bounds on depth and table count, and the schema's file identifier.
#include <cstdint>
#include <span>
#include <string>

#include <flatbuffers/flatbuffers.h>

namespace viscera::protocol::detail {

/// The largest coordinate a received position may have [m]: a scene is metres across, not kilometres.
inline constexpr double kMaxPositionM = 10.0;

/// identifier: the schema's file identifier (4 characters), or nullptr for the schema-1 messages,
/// which have none. max_tables bounds the work a hostile payload can cause.
template <typename T>
const T* verified_root(std::span<const std::uint8_t> bytes, std::string* why, const char* identifier = nullptr,
                       flatbuffers::uoffset_t max_tables = 10000) {
  if (bytes.size() < 8) {
    *why = "payload of " + std::to_string(bytes.size()) + " bytes is too short";
    return nullptr;
  }
  flatbuffers::Verifier v(bytes.data(), bytes.size(), 64, max_tables);
  if (!v.VerifyBuffer<T>(identifier)) {
    *why = "FlatBuffers verification failed (truncated, garbage or another schema)";
    return nullptr;
  }
  return flatbuffers::GetRoot<T>(bytes.data());
}

}  // namespace viscera::protocol::detail
