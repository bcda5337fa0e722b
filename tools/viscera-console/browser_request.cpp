#include "viscera/console/browser_request.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <array>
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "viscera/client/session_limits.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/console/recordings.hpp"

namespace viscera::console {

namespace {

struct TypeInfo {
  RequestType type;
  const char* name;
  std::set<std::string> fields;  ///< besides "type" and "id"
};

const std::array<TypeInfo, 13>& types() {
  static const std::array<TypeInfo, 13> t = {{
      {RequestType::pause, "pause", {}},
      {RequestType::resume, "resume", {}},
      {RequestType::reset, "reset", {}},
      {RequestType::load_scene, "load_scene", {"scene", "seed"}},
      {RequestType::material,
       "material",
       {"youngs-modulus-pa", "poisson-ratio", "density-kg-m3", "shear-q", "damping-per-s", "file-name", "file-text"}},
      {RequestType::annotate, "annotate", {"text"}},
      {RequestType::bookmark, "bookmark", {"label"}},
      {RequestType::watch, "watch", {"station"}},
      {RequestType::take_over, "take_over", {"instrument"}},
      {RequestType::hand_back, "hand_back", {"instrument"}},
      {RequestType::move, "move", {"instrument", "delta_m"}},
      {RequestType::open_recording, "open_recording", {"file"}},
      {RequestType::recordings, "recordings", {}},
  }};
  return t;
}

std::string shown(const nlohmann::json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

}  // namespace

const char* request_type_name(RequestType t) {
  for (const auto& i : types())
    if (i.type == t) return i.name;
  return "?";
}

std::optional<BrowserRequest> parse_browser_request(std::string_view message, std::string* why) {
  const auto fail = [&](std::string w) -> std::optional<BrowserRequest> {
    if (why) *why = std::move(w);
    return std::nullopt;
  };
  if (message.size() > kMaxRequestBytes)
    return fail("request of " + std::to_string(message.size()) + " bytes (at most " + std::to_string(kMaxRequestBytes) + ")");
  const auto parsed = common::try_parse_json(message);  // nesting bounded (common::kMaxJsonDepth)
  if (!parsed) return fail("not JSON");
  const nlohmann::json& j = *parsed;
  if (!j.is_object()) return fail("not a JSON object");
  const auto t = j.find("type");
  if (t == j.end() || !t->is_string()) return fail("type: missing, or not a string");
  const TypeInfo* info = nullptr;
  for (const auto& i : types())
    if (t->get<std::string>() == i.name) info = &i;
  if (!info) {
    std::string known;
    for (const auto& i : types()) known += std::string(known.empty() ? "" : ", ") + i.name;
    return fail("type: " + shown(*t) + " is not one of " + known);
  }
  BrowserRequest r;
  r.type = info->type;
  for (const auto& item : j.items()) {
    const std::string& key = item.key();
    const nlohmann::json& value = item.value();
    if (key == "type") continue;
    if (key == "id") {
      if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 9007199254740991ULL)
        return fail("id: " + shown(value) + " is not a whole number >= 0");
      r.id = value.get<std::uint64_t>();
      continue;
    }
    if (!info->fields.count(key)) return fail(std::string(info->name) + ": unknown field '" + key.substr(0, 40) + "'");
    const auto text = [&](std::size_t max) -> std::optional<std::string> {
      if (!value.is_string()) return std::nullopt;
      std::string s = value.get<std::string>();
      if (s.size() > max) return std::nullopt;
      return s;
    };
    if (key == "scene") {
      const auto s = text(64);
      if (!s || !client::is_scene_name(*s))
        return fail(client::not_a_scene_name(value.is_string() ? value.get<std::string>().substr(0, 64) : shown(value)));
      r.text = *s;
    } else if (key == "seed") {
      if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 9007199254740991ULL)
        return fail("seed: " + shown(value) + " is not a whole number >= 0");
      r.seed = value.get<std::uint64_t>();
    } else if (key == "text" || key == "label") {
      const auto s = text(client::kMaxAnnotationBytes);
      if (!s) return fail(key + ": not a string of at most " + std::to_string(client::kMaxAnnotationBytes) + " bytes");
      r.text = *s;
    } else if (key == "instrument") {
      if (!value.is_number_unsigned() || value.get<std::uint64_t>() == 0 || value.get<std::uint64_t>() > 0xffffffffULL)
        return fail("instrument: " + shown(value) + " is not an instrument id (a whole number >= 1)");
      r.instrument = value.get<std::uint32_t>();
    } else if (key == "delta_m") {
      if (!value.is_array() || value.size() != 3) return fail("delta_m: " + shown(value) + " is not [dx, dy, dz] in metres");
      for (int k = 0; k < 3; ++k) {
        if (!value[k].is_number() || !(std::abs(value[k].get<double>()) <= kMaxMoveStepM))
          return fail("delta_m: " + shown(value) + ": each step within +-" + std::to_string(kMaxMoveStepM).substr(0, 4) + " m");
        r.delta_m[k] = value[k].get<double>();
      }
    } else if (key == "file") {
      const auto s = text(128);
      if (!s || !is_recording_name(*s))
        return fail("file: " + shown(value) + " is not a recording's name (letters, digits, '.', '_', '-', ending in .mcap; no path)");
      r.text = *s;
    } else if (key == "file-name") {
      // A material file's name, for people: any file name, made plain as viscera-control makes it.
      const auto s = text(255);
      if (!s || s->empty()) return fail("file-name: " + shown(value) + " is not a file's name");
      r.change.file_name = client::plain_file_name(*s);
    } else if (key == "file-text") {
      const auto s = text(protocol::kMaxMaterialFileBytes);
      if (!s) return fail("file-text: not a string of at most " + std::to_string(protocol::kMaxMaterialFileBytes) + " bytes");
      r.change.file_text = *s;
    } else if (key == "station") {
      const auto s = text(64);
      if (!s) return fail("station: " + shown(value) + " is not a station name");
      r.text = *s;
    } else {
      for (const auto& p : client::material_parameters())
        if (key == p.name) {
          if (!value.is_number() || !std::isfinite(value.get<double>())) return fail(key + ": " + shown(value) + " is not a number");
          if (const auto w = client::outside_range(key, value.get<double>(), p.lo, p.hi)) return fail(*w);
          r.change.*p.field = value.get<double>();
        }
    }
  }
  if (r.type == RequestType::load_scene && r.text.empty()) return fail("load_scene: scene missing");
  if ((r.type == RequestType::take_over || r.type == RequestType::hand_back || r.type == RequestType::move) && r.instrument == 0)
    return fail(std::string(info->name) + ": instrument missing");
  if (r.type == RequestType::open_recording && r.text.empty()) return fail("open_recording: file missing");
  if (r.type == RequestType::annotate && r.text.empty()) return fail("annotate: text missing or empty");
  if (r.type == RequestType::material && r.change.file_text.has_value() != !r.change.file_name.empty())
    return fail("material: file-text and file-name go together");
  if (r.type == RequestType::material && r.change.empty())
    return fail("material: needs file-text or at least one of youngs-modulus-pa, poisson-ratio, density-kg-m3, shear-q, damping-per-s");
  return r;
}

}  // namespace viscera::console
