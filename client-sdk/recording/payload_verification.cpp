#include "viscera/recording/payload_verification.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/protocol/streams.hpp"

namespace viscera::recording {

bool payload_decodes(protocol::Stream stream, std::span<const std::uint8_t> payload, std::string* why) {
  return protocol::stream_info(stream).verify(payload, why);
}

}  // namespace viscera::recording
