#include "viscera/recording/recording_writer.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <filesystem>

#include "viscera/common/input_error.hpp"
#include "viscera/protocol/binary_schemas.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/recording/recording_format.hpp"

namespace viscera::recording {

namespace proto = viscera::protocol;

std::string attachment_name(const std::string& role, const std::string& path) { return role + "/" + std::filesystem::path(path).filename().string(); }

RecordingWriter::RecordingWriter(const std::string& path, const RecordingInfo& info, mcap::WriterOptions options)
    : writer_(path, std::move(options)), info_(info) {
  std::string streams;
  for (const auto s : info.streams) streams += (streams.empty() ? "" : ",") + std::string(proto::stream_name(s));
  writer_.add_metadata({kRecordingMetadata,
                        {{"schema_version", std::to_string(proto::kSchemaVersion)},
                         {"domain_id", std::to_string(info.domain_id)},
                         {"partition", info.partition},
                         {"streams", streams},
                         {"recorder", info.recorder},
                         {"started_ns", std::to_string(proto::now_ns())}}});
}

std::uint16_t RecordingWriter::channel(const client::TapSample& s, std::uint64_t writer_number) {
  const auto key = std::make_tuple(s.stream, writer_number, s.source_id);
  if (const auto it = channels_.find(key); it != channels_.end()) return it->second;
  auto schema = schemas_.find(s.stream);
  if (schema == schemas_.end()) {
    const proto::BinarySchema b = proto::binary_schema(s.stream);
    schema = schemas_.emplace(s.stream, writer_.add_schema(b.name, kSchemaEncoding, {b.bfbs.begin(), b.bfbs.end()})).first;
  }
  const std::uint16_t id = writer_.add_channel(schema->second, proto::topic_name(s.stream), kMessageEncoding,
                                               {{"stream", proto::stream_name(s.stream)},
                                                {"source_id", std::to_string(s.source_id)},
                                                {"writer", std::to_string(writer_number)},
                                                {"partition", info_.partition}});
  channels_.emplace(key, id);
  return id;
}

void RecordingWriter::add(const client::TapSample& s, std::uint64_t log_time_ns) {
  last_log_time_ = std::max(last_log_time_, log_time_ns);
  const auto [number, fresh] = writer_numbers_.try_emplace(s.writer, writer_numbers_.size() + 1);
  if (fresh) writer_streams_[number->second] = s.stream;
  gaps_.add(number->second, s.seq);
  if (s.stream == proto::Stream::scene_files) return scene_files(s, last_log_time_);
  writer_.add_message(channel(s, number->second), static_cast<std::uint32_t>(s.seq), last_log_time_, static_cast<std::uint64_t>(s.stamp_ns),
                      s.payload);
  ++counts_.messages;
  counts_.bytes += s.payload.size();
  ++counts_.per_stream[s.stream];
}

void RecordingWriter::scene_files(const client::TapSample& s, std::uint64_t log_time) {
  std::string why;
  const auto files = proto::decode_scene_files(s.payload, &why);
  if (!files) {
    ++counts_.undecodable_scene_files;
    return;
  }
  ++counts_.scene_files;
  mcap::Metadata m{kSceneMetadata,
                   {{"generation", std::to_string(files->generation)},
                    {"first_tick", std::to_string(files->first_tick)},
                    {"sim_time_s", common::exact_number(files->sim_time_s)},
                    {"server_version", files->server_version},
                    {"settings_json", files->settings_json},
                    {"log_time_ns", std::to_string(log_time)}}};
  for (const auto& f : files->files) {
    auto known = attached_.find(f.sha256);
    if (known == attached_.end()) {
      // Each content once; a file of the same name with another content (edited between two
      // loads) gets a name of its own.
      std::string name = attachment_name(f.role, f.path);
      for (int k = 2; names_.count(name); ++k) name = attachment_name(f.role, f.path) + "~" + std::to_string(k);
      names_.insert(name);
      const std::string media = f.role == "mesh" ? "application/octet-stream" : "application/json";
      writer_.add_attachment({log_time, log_time, name, media, f.content});
      ++counts_.attachments;
      known = attached_.emplace(f.sha256, name).first;
    }
    m.values[f.role + ".attachment"] = known->second;
    m.values[f.role + ".sha256"] = f.sha256;
    m.values[f.role + ".path"] = f.path;
  }
  writer_.add_metadata(m);
}

void RecordingWriter::close() {
  if (closed_) return;
  closed_ = true;
  mcap::Metadata drops{kDropsMetadata, {{"missing", std::to_string(gaps_.missing())}}};
  for (const auto& [number, w] : gaps_.writers()) {
    const std::string key = "writer." + std::to_string(number);
    drops.values[key] = std::string(proto::stream_name(writer_streams_.at(number))) + " received " + std::to_string(w.received) + " missing " +
                        std::to_string(w.missing) + " gaps " + std::to_string(w.gaps) + " out_of_order " + std::to_string(w.out_of_order) + " seq " +
                        std::to_string(w.first) + "-" + std::to_string(w.last);
  }
  writer_.add_metadata(drops);
  writer_.close();
}

}  // namespace viscera::recording
