#include "viscera/console/foxglove_protocol.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cstring>

#include "viscera/common/json_input.hpp"
#include "viscera/protocol/binary_schemas.hpp"
#include "viscera/protocol/messages.hpp"

namespace viscera::console {

namespace proto = viscera::protocol;

const std::vector<proto::Stream>& foxglove_streams() {
  static const std::vector<proto::Stream> s = {proto::Stream::instrument_command, proto::Stream::force_feedback, proto::Stream::session_request,
                                               proto::Stream::scene_state,        proto::Stream::telemetry,      proto::Stream::surface_topology,
                                               proto::Stream::mesh_frame,         proto::Stream::event,          proto::Stream::scene_files};
  return s;
}

std::uint32_t foxglove_channel(proto::Stream s) { return static_cast<std::uint32_t>(s) + 1; }

std::string base64(std::span<const std::uint8_t> bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t{bytes[i]} << 16) | (i + 1 < bytes.size() ? std::uint32_t{bytes[i + 1]} << 8 : 0U) |
                            (i + 2 < bytes.size() ? std::uint32_t{bytes[i + 2]} : 0U);
    out += alphabet[(n >> 18) & 63];
    out += alphabet[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[n & 63] : '=';
  }
  return out;
}

nlohmann::json foxglove_server_info(const std::string& name) {
  return {{"op", "serverInfo"},
          {"name", name},
          {"capabilities", nlohmann::json::array()},
          {"supportedEncodings", nlohmann::json::array()},
          {"metadata", {{"schema_version", std::to_string(proto::kSchemaVersion)}}},
          {"sessionId", name}};
}

nlohmann::json foxglove_advertise() {
  nlohmann::json channels = nlohmann::json::array();
  for (const proto::Stream s : foxglove_streams()) {
    const proto::BinarySchema b = proto::binary_schema(s);
    channels.push_back({{"id", foxglove_channel(s)},
                        {"topic", proto::topic_name(s)},
                        {"encoding", "flatbuffer"},
                        {"schemaName", b.name},
                        {"schema", base64(b.bfbs)},
                        {"schemaEncoding", "flatbuffer"}});
  }
  return {{"op", "advertise"}, {"channels", channels}};
}

std::string foxglove_message_data(std::uint32_t subscription, std::uint64_t receive_ns, std::span<const std::uint8_t> payload) {
  std::string out(13 + payload.size(), '\0');
  out[0] = 1;
  std::memcpy(out.data() + 1, &subscription, 4);  // little-endian hosts only
  std::memcpy(out.data() + 5, &receive_ns, 8);
  if (!payload.empty()) std::memcpy(out.data() + 13, payload.data(), payload.size());
  return out;
}

nlohmann::json foxglove_status(int level, const std::string& message) { return {{"op", "status"}, {"level", level}, {"message", message}}; }

std::optional<std::string> FoxgloveSubscriptions::apply(std::string_view message) {
  const nlohmann::json j = common::try_parse_json(message).value_or(nlohmann::json());
  if (!j.is_object() || !j.contains("op") || !j["op"].is_string()) return "not a JSON object with an \"op\"";
  const std::string op = j["op"].get<std::string>();
  const auto is_id = [](const nlohmann::json& v) { return v.is_number_unsigned() && v.get<std::uint64_t>() <= 0xffffffffULL; };
  if (op == "subscribe") {
    if (!j.contains("subscriptions") || !j["subscriptions"].is_array()) return "subscribe: subscriptions missing";
    for (const auto& s : j["subscriptions"]) {
      if (!s.is_object() || !s.contains("id") || !s.contains("channelId") || !is_id(s["id"]) || !is_id(s["channelId"]))
        return "subscribe: each subscription needs a whole-number id and channelId";
      const auto id = s["id"].get<std::uint32_t>(), channel = s["channelId"].get<std::uint32_t>();
      const bool known =
          std::any_of(foxglove_streams().begin(), foxglove_streams().end(), [&](proto::Stream x) { return foxglove_channel(x) == channel; });
      if (!known) return "subscribe: no channel " + std::to_string(channel);
      if (subscriptions_.count(id)) return "subscribe: subscription id " + std::to_string(id) + " is in use";
      if (subscriptions_.size() >= 64) return "subscribe: at most 64 subscriptions";
      subscriptions_[id] = channel;
    }
    return std::nullopt;
  }
  if (op == "unsubscribe") {
    if (!j.contains("subscriptionIds") || !j["subscriptionIds"].is_array()) return "unsubscribe: subscriptionIds missing";
    for (const auto& id : j["subscriptionIds"]) {
      if (!is_id(id)) return "unsubscribe: ids are whole numbers";
      subscriptions_.erase(id.get<std::uint32_t>());
    }
    return std::nullopt;
  }
  return "op '" + op.substr(0, 40) + "' is not supported (subscribe, unsubscribe)";
}

std::vector<std::uint32_t> FoxgloveSubscriptions::to(std::uint32_t channel) const {
  std::vector<std::uint32_t> out;
  for (const auto& [id, c] : subscriptions_)
    if (c == channel) out.push_back(id);
  return out;
}

}  // namespace viscera::console
