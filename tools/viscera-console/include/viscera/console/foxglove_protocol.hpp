#pragma once  // SPDX-License-Identifier: Apache-2.0
// The Foxglove WebSocket protocol (subprotocol "foxglove.websocket.v1"), the server's side, so
// that Foxglove or Lichtblick attach to a live session as they open its MCAP recordings: each
// stream is a channel advertised with its binary FlatBuffers schema (as the recorder stores it,
// encoding "flatbuffer"); a client subscribes to channels and receives each payload as it came off
// the domain. Only the parts a viewer needs: serverInfo, advertise, subscribe, unsubscribe,
// messageData, status.
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "viscera/protocol/dds.hpp"

namespace viscera::console {

inline constexpr const char* kFoxgloveSubprotocol = "foxglove.websocket.v1";

/// The channel id of a stream (its place in the protocol's list, from 1).
std::uint32_t foxglove_channel(protocol::Stream s);
/// The streams a live session offers as channels.
const std::vector<protocol::Stream>& foxglove_streams();

/// {"op": "serverInfo", ...}: the first message to a client.
nlohmann::json foxglove_server_info(const std::string& name);
/// {"op": "advertise", "channels": [...]}: every channel with its topic and base64 schema.
nlohmann::json foxglove_advertise();
/// The binary messageData frame: [u8 1][u32 subscription id][u64 receive time ns][payload].
std::string foxglove_message_data(std::uint32_t subscription, std::uint64_t receive_ns, std::span<const std::uint8_t> payload);
/// {"op": "status", "level": 0 info | 1 warning | 2 error, "message": ...}
nlohmann::json foxglove_status(int level, const std::string& message);

std::string base64(std::span<const std::uint8_t> bytes);

/// One client's subscriptions: subscription id -> channel id, from its subscribe and unsubscribe
/// messages, checked (known channels only, ids not reused, at most 64).
class FoxgloveSubscriptions {
 public:
  /// Applies a client message; nothing on success, else why (sent back as a status).
  std::optional<std::string> apply(std::string_view message);
  /// The subscriptions to `channel`.
  std::vector<std::uint32_t> to(std::uint32_t channel) const;
  bool any() const { return !subscriptions_.empty(); }

 private:
  std::map<std::uint32_t, std::uint32_t> subscriptions_;
};

}  // namespace viscera::console
