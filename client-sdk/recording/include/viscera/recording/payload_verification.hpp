#pragma once  // SPDX-License-Identifier: Apache-2.0
// A recorded payload checked by viscera's own decoder of its stream: the FlatBuffers verifier,
// then every range and finiteness check a live receiver applies (`viscera-record info --verify`).
#include <cstdint>
#include <span>
#include <string>

#include "viscera/protocol/dds.hpp"

namespace viscera::recording {

/// True when the payload decodes as its stream's message; otherwise `why` says what is wrong.
bool payload_decodes(protocol::Stream stream, std::span<const std::uint8_t> payload, std::string* why);

}  // namespace viscera::recording
