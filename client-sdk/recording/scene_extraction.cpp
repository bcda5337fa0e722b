#include "viscera/recording/scene_extraction.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/protocol/messages.hpp"

namespace viscera::recording {

namespace fs = std::filesystem;
using common::InputError;
using nlohmann::json;

namespace {

/// A recorded file's content, checked against its digest.
std::vector<std::uint8_t> content(Recording& r, const RecordedFile& f) {
  auto bytes = r.attachment(f.attachment);
  if (protocol::sha256_hex(bytes) != f.sha256)
    throw InputError(r.path(), 0, "attachment " + f.attachment, "its content does not match its SHA-256 " + f.sha256 + " (damaged)");
  return bytes;
}

/// A scene file's JSON, with what this file reads of it checked for its type: an object with an
/// organ object that names its mesh and material (the scene reader checks the rest).
json parse_scene(std::string_view text, const std::string& source) {
  json j = common::parse_json(text, source);
  const common::JsonObject organ = common::JsonObject(j, source).object("organ");
  organ.text("mesh");
  organ.text("material");
  return j;
}

json parse(const std::vector<std::uint8_t>& bytes, const std::string& source) {
  return parse_scene(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), source);
}

/// What makes the organ the same organ (its geometry and its instruments), as "field: value",
/// with the scene format's defaults (docs/SCENE.md) for what a file leaves out.
std::vector<std::pair<std::string, json>> organ_identity(const json& scene) {
  std::vector<std::pair<std::string, json>> out;
  const json organ = scene.value("organ", json::object());
  out.emplace_back("organ.scale_m_per_unit", organ.value("scale_m_per_unit", json(1.0)));
  out.emplace_back("organ.refine", organ.value("refine", json(0)));
  out.emplace_back("organ.fix_slab", organ.value("fix_slab", json::array({"z", "max", 0.2})));
  out.emplace_back("instruments", scene.value("instruments", json::array()));
  return out;
}

}  // namespace

ExtractedScenes extract_scenes(Recording& recording, const std::string& dir, const std::optional<std::string>& replacement) {
  if (recording.scenes().empty()) throw InputError(recording.path(), 0, "viscera.scene", "missing: the recording holds no scene files");
  ExtractedScenes out;
  out.scene_dir = (fs::path(dir) / "scenes").string();
  const fs::path files = fs::path(dir) / "files";
  fs::create_directories(out.scene_dir);
  fs::create_directories(files);
  std::vector<const RecordedScene*> order;
  for (const auto& s : recording.scenes()) order.push_back(&s);
  std::stable_sort(order.begin(), order.end(), [](const auto* a, const auto* b) { return a->log_time_ns < b->log_time_ns; });
  for (const RecordedScene* s : order) {
    const RecordedFile* scene = s->file("scene");
    const RecordedFile* mesh = s->file("mesh");
    const RecordedFile* material = s->file("material");
    if (!scene || !mesh || !material)
      throw InputError(recording.path(), 0, "viscera.scene",
                       "generation " + std::to_string(s->generation) + " lacks its scene, mesh or material file");
    const auto write = [&](const RecordedFile& f) {
      const fs::path p = files / (f.sha256.substr(0, 12) + "-" + fs::path(f.path).filename().string());
      common::write_file_bytes(p.string(), content(recording, f));
      return fs::absolute(p).string();
    };
    json j = parse(content(recording, *scene), recording.path() + " (attachment " + scene->attachment + ")");
    j["organ"]["mesh"] = write(*mesh);
    j["organ"]["material"] = write(*material);
    if (j["organ"].contains("regions") && j["organ"]["regions"].is_array())
      for (std::size_t k = 0; k < j["organ"]["regions"].size(); ++k) {
        const RecordedFile* region = s->file(protocol::region_material_role(k));
        if (!region)
          throw InputError(recording.path(), 0, "viscera.scene",
                           "generation " + std::to_string(s->generation) + " lacks the material file of its region " + std::to_string(k));
        j["organ"]["regions"][k]["material"] = write(*region);
      }
    const std::string stem = fs::path(scene->path).stem().string();
    const fs::path path = fs::path(out.scene_dir) / (stem + ".json");
    const std::string text = j.dump(2);
    common::write_file_bytes(path.string(), std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    if (out.first_scene.empty()) out.first_scene = path.string();
  }
  if (!replacement) return out;

  // The replacement: the same organ, other physics.
  const RecordedScene& first = *order.front();
  const json recorded = parse(content(recording, *first.file("scene")), recording.path());
  const json here = parse_scene(common::read_text_file(*replacement, std::size_t{16} << 20), *replacement);
  const json replacement_organ = here.value("organ", json::object());
  const std::string mesh_path = (fs::path(*replacement).parent_path() / replacement_organ.value("mesh", std::string())).string();
  const std::string recorded_name = recorded.value("name", fs::path(first.file("scene")->path).stem().string());
  const auto another = [&](const std::string& field, const std::string& what) {
    throw InputError(*replacement, 0, field, what + ": a recording of another scene (" + recorded_name + ") cannot be re-simulated on it");
  };
  try {
    if (protocol::sha256_hex(common::read_file_bytes(mesh_path)) != first.file("mesh")->sha256)
      another("organ.mesh", mesh_path + " is another mesh than the recording's");
  } catch (const InputError& e) {
    if (e.source() == *replacement) throw;
    throw InputError(*replacement, 0, "organ.mesh", e.what());
  }
  const auto mine = organ_identity(here), theirs = organ_identity(recorded);
  for (std::size_t k = 0; k < mine.size(); ++k)
    if (mine[k].second != theirs[k].second) another(mine[k].first, mine[k].second.dump() + " here, " + theirs[k].second.dump() + " in the recording");
  // What differs (the what-if), then the replacement with its paths made absolute.
  const json organ_here = here.value("organ", json::object()), organ_recorded = recorded.value("organ", json::object());
  json changed = here;
  const fs::path base = fs::path(*replacement).parent_path();
  changed["organ"]["mesh"] = fs::absolute(base / organ_here.value("mesh", std::string())).string();
  changed["organ"]["material"] = fs::absolute(base / organ_here.value("material", std::string())).string();
  if (changed["organ"].contains("regions") && changed["organ"]["regions"].is_array())
    for (auto& region : changed["organ"]["regions"])
      if (region.is_object() && region.contains("material") && region["material"].is_string())
        region["material"] = fs::absolute(base / region["material"].get<std::string>()).string();
  const auto material_bytes = common::read_file_bytes(changed["organ"]["material"].get<std::string>());
  if (protocol::sha256_hex(material_bytes) != first.file("material")->sha256)
    out.differences.push_back("organ.material: " + changed["organ"]["material"].get<std::string>() + " (another material file than the recording's " +
                              first.file("material")->path + ")");
  for (const auto& [k, v] : organ_here.items())
    if (k != "mesh" && k != "material" && organ_recorded.value(k, json()) != v)
      out.differences.push_back("organ." + k + ": " + v.dump() + " (recorded " + organ_recorded.value(k, json()).dump() + ")");
  for (const auto& [k, v] : here.items())
    if (k != "organ" && k != "instruments" && recorded.value(k, json()) != v)
      out.differences.push_back(k + ": " + v.dump() + " (recorded " + recorded.value(k, json()).dump() + ")");
  const fs::path path = fs::path(out.scene_dir) / fs::path(out.first_scene).filename();
  const std::string text = changed.dump(2);
  common::write_file_bytes(path.string(), std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  return out;
}

}  // namespace viscera::recording
