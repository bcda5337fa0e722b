#pragma once  // SPDX-License-Identifier: Apache-2.0
// The schema of each stream's payloads as a binary FlatBuffers schema (flatc --binary --schema,
// the reflection format), embedded at build time: recordings carry it (MCAP schema encoding
// "flatbuffer"), so other people's tools decode viscera's messages without viscera's code.
#include <cstdint>
#include <span>
#include <string>

#include "viscera/protocol/dds.hpp"

namespace viscera::protocol {

struct BinarySchema {
  std::string name;  ///< the root table's fully qualified name ("viscera.wire.ForceFeedback")
  std::span<const std::uint8_t> bfbs;  ///< the .bfbs of the schema file that defines it (with what it includes)
};

/// The binary schema of the payloads on `s`.
BinarySchema binary_schema(Stream s);

}  // namespace viscera::protocol
