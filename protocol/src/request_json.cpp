#include "viscera/protocol/request_json.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::protocol {

namespace {
constexpr Action kActions[] = {
    Action::claim_instrument, Action::release_instrument, Action::pause, Action::resume,    Action::reset,    Action::load_scene,
    Action::set_material,     Action::set_physics_rate,   Action::seek,  Action::take_over, Action::hand_back};
}  // namespace

nlohmann::json to_json(const SessionRequest& r) {
  nlohmann::json j = {{"action", action_name(r.action)}, {"client_id", r.client_id}, {"request_seq", r.request_seq}};
  if (r.action == Action::claim_instrument || r.action == Action::release_instrument || r.action == Action::take_over ||
      r.action == Action::hand_back)
    j["instrument_id"] = r.instrument_id;
  if (r.action == Action::load_scene) j["scene_name"] = r.scene_name;
  if (r.action == Action::load_scene && r.scene_seed) j["scene_seed"] = *r.scene_seed;
  if (r.action == Action::set_physics_rate) j["physics_rate_hz"] = r.physics_rate_hz;
  if (r.action == Action::seek) j["seek_s"] = r.seek_s;
  if (r.action == Action::set_material) {
    nlohmann::json m = nlohmann::json::object();
    const auto put = [&](const char* name, const std::optional<double>& v) {
      if (v) m[name] = *v;
    };
    put("youngs_modulus_pa", r.material.youngs_modulus_pa);
    put("poisson_ratio", r.material.poisson_ratio);
    put("density_kg_m3", r.material.density_kg_m3);
    put("shear_q", r.material.shear_q);
    put("damping_per_s", r.material.damping_per_s);
    if (r.material.file_text) {
      m["file_name"] = r.material.file_name;
      m["file_text"] = *r.material.file_text;
    }
    j["material"] = m;
  }
  return j;
}

std::optional<SessionRequest> session_request_from_json(const nlohmann::json& j, std::string* why) {
  try {
    SessionRequest r;
    const std::string action = j.at("action").get<std::string>();
    bool known = false;
    for (const Action a : kActions)
      if (action == action_name(a)) {
        r.action = a;
        known = true;
      }
    if (!known) {
      *why = "action '" + action + "' is not a session action";
      return std::nullopt;
    }
    r.client_id = j.at("client_id").get<std::uint32_t>();
    r.request_seq = j.value("request_seq", std::uint64_t{0});
    r.instrument_id = j.value("instrument_id", std::uint32_t{0});
    r.scene_name = j.value("scene_name", std::string());
    r.physics_rate_hz = j.value("physics_rate_hz", 0.0);
    r.seek_s = j.value("seek_s", 0.0);
    if (j.contains("scene_seed")) r.scene_seed = j.at("scene_seed").get<std::uint64_t>();
    if (const auto m = j.find("material"); m != j.end()) {
      const auto get = [&](const char* name, std::optional<double>& out) {
        if (m->contains(name)) out = m->at(name).get<double>();
      };
      get("youngs_modulus_pa", r.material.youngs_modulus_pa);
      get("poisson_ratio", r.material.poisson_ratio);
      get("density_kg_m3", r.material.density_kg_m3);
      get("shear_q", r.material.shear_q);
      get("damping_per_s", r.material.damping_per_s);
      if (m->contains("file_text")) {
        r.material.file_text = m->at("file_text").get<std::string>();
        r.material.file_name = m->value("file_name", std::string());
      }
    }
    return decode_session_request(encode(r), why);  // the checks every received request passes
  } catch (const nlohmann::json::exception& e) {
    *why = e.what();
    return std::nullopt;
  }
}

}  // namespace viscera::protocol
