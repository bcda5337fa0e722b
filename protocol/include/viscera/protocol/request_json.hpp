#pragma once  // SPDX-License-Identifier: Apache-2.0
// A session request as JSON, for what people read and tools re-run: the material and rate changes
// a scene went through (SceneFiles settings), and reports. Field names are the schema's.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "viscera/protocol/messages.hpp"

namespace viscera::protocol {

/// {"action": "set_material", "client_id": 7, "request_seq": 3, "material": {"youngs_modulus_pa": 8000}}
/// (instrument_id, scene_name, physics_rate_hz and material only where the action uses them).
nlohmann::json to_json(const SessionRequest& r);
/// The request back, checked as a received one is (the same decoder); nullopt and why otherwise.
std::optional<SessionRequest> session_request_from_json(const nlohmann::json& j, std::string* why);

}  // namespace viscera::protocol
