#include "viscera/recording/recording.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <future>

#include "viscera/common/input_error.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/recording/recording_format.hpp"

namespace viscera::recording {

namespace proto = viscera::protocol;
using common::InputError;

namespace {
std::uint64_t parse_u64(const std::map<std::string, std::string>& m, const std::string& key, const std::string& path, const std::string& record) {
  const auto it = m.find(key);
  if (it == m.end()) throw InputError(path, 0, record + "." + key, "missing");
  std::string why;
  const auto v = common::read_integer(it->second, &why);
  if (!v) throw InputError(path, 0, record + "." + key, why);
  if (*v < 0) throw InputError(path, 0, record + "." + key, common::outside(*v, 0LL, std::numeric_limits<long long>::max()));
  return static_cast<std::uint64_t>(*v);
}
}  // namespace

std::uint32_t Recording::domain_id() const {
  const auto it = info_.find("domain_id");
  if (it == info_.end()) return 0;
  std::string why;
  const auto v = common::read_integer(it->second, &why);
  if (!v) throw InputError(path(), 0, "viscera.recording.domain_id", why);
  if (*v < 0 || *v > 230) throw InputError(path(), 0, "viscera.recording.domain_id", common::outside(*v, 0LL, 230LL));
  return static_cast<std::uint32_t>(*v);
}

const RecordedFile* RecordedScene::file(const std::string& role) const {
  for (const auto& f : files)
    if (f.role == role) return &f;
  return nullptr;
}

Recording::Recording(const std::string& path) : reader_(path) {
  auto s = reader_.summary();
  if (!s)
    throw InputError(
        path, 0, "",
        "has no summary: the recording was cut short (its recorder was killed?); make it whole with: viscera-record recover " + path + " OUT.mcap");
  summary_ = std::move(*s);
  for (const auto& index : summary_.metadata) {
    if (index.name != kRecordingMetadata && index.name != kSceneMetadata && index.name != kDropsMetadata) continue;
    const mcap::Metadata m = reader_.read_metadata(index);
    if (m.name == kRecordingMetadata) info_ = m.values;
    if (m.name == kDropsMetadata) drops_ = m.values;
    if (m.name == kSceneMetadata) {
      RecordedScene scene;
      scene.generation = static_cast<std::uint32_t>(parse_u64(m.values, "generation", path, m.name));
      scene.first_tick = parse_u64(m.values, "first_tick", path, m.name);
      scene.log_time_ns = parse_u64(m.values, "log_time_ns", path, m.name);
      const auto sim = m.values.find("sim_time_s");
      if (sim == m.values.end()) throw InputError(path, 0, m.name + ".sim_time_s", "missing");
      std::string why;
      const auto sim_time = common::read_number(sim->second, &why);
      if (!sim_time) throw InputError(path, 0, m.name + ".sim_time_s", why);
      scene.sim_time_s = *sim_time;
      scene.server_version = m.values.count("server_version") ? m.values.at("server_version") : "";
      scene.settings_json = m.values.count("settings_json") ? m.values.at("settings_json") : "";
      std::vector<std::string> roles{"scene", "mesh", "material"};
      for (std::size_t k = 0; m.values.count(protocol::region_material_role(k) + ".attachment"); ++k)
        roles.push_back(protocol::region_material_role(k));
      for (const std::string& role : roles)
        if (m.values.count(role + ".attachment"))
          scene.files.push_back({role, m.values.count(role + ".path") ? m.values.at(role + ".path") : "", m.values.at(role + ".attachment"),
                                 m.values.count(role + ".sha256") ? m.values.at(role + ".sha256") : ""});
      scenes_.push_back(std::move(scene));
    }
  }
  if (info_.empty()) throw InputError(path, 0, kRecordingMetadata, "missing: an MCAP file, but not a viscera session recording");
  const std::uint64_t schema = parse_u64(info_, "schema_version", path, kRecordingMetadata);
  if (schema > static_cast<std::uint64_t>(proto::kSchemaVersion))
    throw InputError(path, 0, std::string(kRecordingMetadata) + ".schema_version",
                     std::to_string(schema) + ": recorded by a newer viscera (this build reads protocol schemas up to " +
                         std::to_string(proto::kSchemaVersion) + ")");
  for (const auto& c : summary_.channels) {
    RecordedChannel rc;
    rc.id = c.id;
    const auto stream = c.metadata.find("stream");
    if (stream == c.metadata.end() || !proto::parse_stream(stream->second, &rc.stream)) continue;  // another tool's channel, or newer
    rc.source_id = static_cast<std::uint32_t>(parse_u64(c.metadata, "source_id", path, "channel " + c.topic));
    rc.writer = parse_u64(c.metadata, "writer", path, "channel " + c.topic);
    channels_[c.id] = rc;
  }
}

std::vector<std::uint8_t> Recording::attachment(const std::string& name) {
  for (const auto& a : summary_.attachments)
    if (a.name == name) return reader_.read_attachment(a).data;
  throw InputError(path(), 0, "attachment " + name, "not in the recording");
}

mcap::Integrity Recording::integrity() { return mcap::check_integrity(reader_); }

std::uint64_t Recording::start_ns() const { return summary_.statistics ? summary_.statistics->message_start_time : 0; }
std::uint64_t Recording::end_ns() const { return summary_.statistics ? summary_.statistics->message_end_time : 0; }

void Recording::for_each(const std::function<bool(const RecordedChannel&, const mcap::Message&)>& f, std::uint64_t from_ns, std::uint64_t to_ns,
                         bool read_ahead) {
  std::vector<mcap::ChunkIndex> chunks;
  for (const auto& c : summary_.chunks)
    if (c.end_time >= from_ns && c.start_time <= to_ns) chunks.push_back(c);
  std::stable_sort(chunks.begin(), chunks.end(), [](const auto& a, const auto& b) { return a.start_time < b.start_time; });
  const auto load = [this](const mcap::ChunkIndex& c) {
    std::vector<mcap::Message> messages = reader_.read_chunk(c);
    std::stable_sort(messages.begin(), messages.end(), [](const auto& a, const auto& b) { return a.log_time < b.log_time; });
    return messages;
  };
  // With read_ahead, the next chunk is read, decompressed and checked on a thread of its own while
  // `f` takes this one's messages (f must not use this recording meanwhile).
  std::future<std::vector<mcap::Message>> next;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    std::vector<mcap::Message> messages = next.valid() ? next.get() : load(chunks[i]);
    if (read_ahead && i + 1 < chunks.size()) next = std::async(std::launch::async, load, chunks[i + 1]);
    for (const auto& m : messages) {
      if (m.log_time < from_ns || m.log_time > to_ns) continue;
      const auto ch = channels_.find(m.channel_id);
      if (ch == channels_.end()) continue;
      if (!f(ch->second, m)) return;  // a chunk still being read is waited for (std::future's destructor)
    }
  }
}

}  // namespace viscera::recording
