// viscera-record: records a session (every viscera stream of a DDS domain and partition) to MCAP;  // SPDX-License-Identifier: Apache-2.0
// recovers a recording cut short; prints what a recording holds. docs/RECORDING.md.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "viscera/client/stream_tap.hpp"
#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/mcap/mcap_reader.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/recording/payload_verification.hpp"
#include "viscera/recording/recording.hpp"
#include "viscera/recording/recording_writer.hpp"

namespace {

namespace proto = viscera::protocol;
namespace rec = viscera::recording;
using viscera::common::UsageError;

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

std::vector<proto::Stream> parse_topics(const std::string& list) {
  if (list.empty()) return viscera::client::session_streams();
  std::vector<proto::Stream> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    std::string name = list.substr(start, comma - start);
    if (name.rfind("viscera_", 0) == 0) name = name.substr(8);
    proto::Stream s{};
    const auto session = viscera::client::session_streams();
    if (!proto::parse_stream(name, &s) || std::find(session.begin(), session.end(), s) == session.end()) {
      std::string names;
      for (const auto r : session) names += std::string(names.empty() ? "" : ", ") + proto::stream_name(r);
      throw UsageError("--topics: '" + list.substr(start, comma - start) + "' is not a session stream (" + names + ")");
    }
    out.push_back(s);
    start = comma + 1;
  }
  return out;
}

std::string megabytes(std::uint64_t bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return b;
}

int record(const viscera::common::CommandLine& cl) {
  rec::RecordingInfo info;
  info.domain_id = static_cast<std::uint32_t>(cl.integer_in("domain", 0, 230));
  info.partition = proto::checked_station(cl.text("station"));
  info.streams = parse_topics(cl.text("topics"));
  info.recorder = "viscera-record, protocol schema " + std::to_string(proto::kSchemaVersion);
  viscera::mcap::WriterOptions options;
  options.compression = cl.text("compression") == "none" ? "" : cl.text("compression");
  if (options.compression != "" && options.compression != "zstd" && options.compression != "lz4")
    throw UsageError("--compression: '" + cl.text("compression") + "' is not zstd, lz4 or none");
  options.chunk_bytes = static_cast<std::size_t>(cl.number_in("chunk-mb", 0.01, 1024) * 1024 * 1024);
  options.chunk_ns = static_cast<std::uint64_t>(cl.number_in("chunk-s", 0.01, 3600) * 1e9);
  options.library = info.recorder;
  options.replace = cl.has("replace");
  const double duration = cl.number_in("duration", 0, 1e7);
  const int depth = static_cast<int>(cl.integer_in("depth", 1, 1000000));
  const bool quiet = cl.has("quiet");
  const std::string out = cl.text("out");

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  rec::RecordingWriter writer(out, info, options);
  viscera::client::StreamTap tap(info.domain_id, info.partition, info.streams, depth);
  std::printf("viscera-record: recording DDS domain %u%s%s to %s (%s chunks of %.1f MiB or %.1f s)%s\n", info.domain_id,
              info.partition.empty() ? "" : ", station ", info.partition.c_str(), out.c_str(),
              options.compression.empty() ? "uncompressed" : options.compression.c_str(), static_cast<double>(options.chunk_bytes) / 1048576.0,
              1e-9 * static_cast<double>(options.chunk_ns), duration > 0 ? "" : "; Ctrl-C stops");
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  auto last_status = start;
  while (!g_stop.load()) {
    tap.wait(std::chrono::milliseconds(5));
    const auto now_ns = static_cast<std::uint64_t>(proto::now_ns());
    tap.take([&](const viscera::client::TapSample& s) { writer.add(s, now_ns); });
    writer.flush_if_due(now_ns);
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (!quiet && now - last_status >= std::chrono::seconds(1)) {
      last_status = now;
      const auto& c = writer.counts();
      const auto n = [&](proto::Stream s) { return c.per_stream.count(s) ? c.per_stream.at(s) : 0; };
      std::printf("viscera-record: %.0f s, %llu messages (commands %llu, forces %llu, frames %llu, events %llu), %s written, %llu missing\n", elapsed,
                  static_cast<unsigned long long>(c.messages), static_cast<unsigned long long>(n(proto::Stream::instrument_command)),
                  static_cast<unsigned long long>(n(proto::Stream::force_feedback)), static_cast<unsigned long long>(n(proto::Stream::mesh_frame)),
                  static_cast<unsigned long long>(n(proto::Stream::event)), megabytes(writer.file_bytes()).c_str(),
                  static_cast<unsigned long long>(writer.gaps().missing()));
      std::fflush(stdout);
    }
    if (duration > 0 && elapsed >= duration) break;
  }
  // What arrived while stopping is kept.
  tap.take([&](const viscera::client::TapSample& s) { writer.add(s, static_cast<std::uint64_t>(proto::now_ns())); });
  writer.close();
  const auto& c = writer.counts();
  std::printf("viscera-record: wrote %s: %llu messages, %s of payloads, %s file, %llu scene files (%llu attachments), %llu missing\n", out.c_str(),
              static_cast<unsigned long long>(c.messages), megabytes(c.bytes).c_str(), megabytes(writer.file_bytes()).c_str(),
              static_cast<unsigned long long>(c.scene_files), static_cast<unsigned long long>(c.attachments),
              static_cast<unsigned long long>(writer.gaps().missing()));
  for (const auto& [number, w] : writer.gaps().writers())
    std::printf("  writer %llu (%s): %llu received, %llu missing in %llu gaps%s\n", static_cast<unsigned long long>(number),
                proto::stream_name(writer.writer_streams().at(number)), static_cast<unsigned long long>(w.received),
                static_cast<unsigned long long>(w.missing), static_cast<unsigned long long>(w.gaps),
                w.out_of_order ? (", " + std::to_string(w.out_of_order) + " out of order").c_str() : "");
  return 0;
}

int recover(const std::vector<std::string>& args) {
  if (args.size() != 3) throw UsageError("recover takes IN.mcap OUT.mcap");
  const auto end = viscera::mcap::recover(args[1], args[2]);
  const std::string in = viscera::common::printable(args[1], 200), out = viscera::common::printable(args[2], 200);
  if (end.complete && end.intact())
    std::printf("viscera-record: %s was whole; %s has its %llu messages in %llu chunks\n", in.c_str(), out.c_str(),
                static_cast<unsigned long long>(end.messages), static_cast<unsigned long long>(end.chunks));
  else
    std::printf("viscera-record: saved %llu messages in %llu intact chunks and %llu attachments to %s; %s %s\n",
                static_cast<unsigned long long>(end.messages), static_cast<unsigned long long>(end.chunks),
                static_cast<unsigned long long>(end.attachments), out.c_str(), in.c_str(),
                end.complete ? "reached its Data End" : ("ends at byte " + std::to_string(end.offset) + ": " + end.error).c_str());
  std::uint64_t lost = 0;
  for (const auto& d : end.damaged) {
    lost += d.length;
    const std::uint64_t end_byte = d.offset + d.length;
    std::printf("viscera-record: lost bytes %llu to %llu (%llu bytes): %s\n", static_cast<unsigned long long>(d.offset),
                static_cast<unsigned long long>(end_byte), static_cast<unsigned long long>(d.length), d.what.c_str());
  }
  if (lost == 0) return 0;
  std::printf("viscera-record: %llu bytes of %s could not be recovered (exit 1)\n", static_cast<unsigned long long>(lost), in.c_str());
  return 1;
}

/// Text from the file, printed with every byte a terminal could act on escaped.
std::string shown(const std::string& text) { return viscera::common::printable(text, 400); }

std::string seconds(std::uint64_t ns) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f s", 1e-9 * static_cast<double>(ns));
  return b;
}

int info(const std::vector<std::string>& args, bool verify) {
  if (args.size() != 2) throw UsageError("info takes FILE.mcap");
  rec::Recording r(args[1]);
  const auto& s = r.summary();
  std::printf("%s: viscera recording, protocol schema %s, DDS domain %s%s%s, by %s\n", shown(r.path()).c_str(),
              shown(r.info().at("schema_version")).c_str(), r.info().count("domain_id") ? shown(r.info().at("domain_id")).c_str() : "?",
              r.info().count("partition") && !r.info().at("partition").empty() ? ", station " : "",
              r.info().count("partition") ? shown(r.info().at("partition")).c_str() : "",
              r.info().count("recorder") ? shown(r.info().at("recorder")).c_str() : "?");
  const std::uint64_t span = r.end_ns() - r.start_ns();
  std::printf("  %llu messages over %s, %zu chunks, %zu channels, %zu schemas, %zu attachments\n",
              static_cast<unsigned long long>(s.statistics ? s.statistics->message_count : 0), seconds(span).c_str(), s.chunks.size(),
              s.channels.size(), s.schemas.size(), s.attachments.size());
  for (const auto& sch : s.schemas)
    std::printf("  schema %u: %s (%s, %zu bytes)\n", sch.id, shown(sch.name).c_str(), shown(sch.encoding).c_str(), sch.data.size());
  for (const auto& c : s.channels) {
    const std::uint64_t n = s.statistics && s.statistics->channel_message_counts.count(c.id) ? s.statistics->channel_message_counts.at(c.id) : 0;
    std::printf("  channel %u: %s, source %s, writer %s, schema %u: %llu messages\n", c.id, shown(c.topic).c_str(),
                c.metadata.count("source_id") ? shown(c.metadata.at("source_id")).c_str() : "?",
                c.metadata.count("writer") ? shown(c.metadata.at("writer")).c_str() : "?", c.schema_id, static_cast<unsigned long long>(n));
  }
  for (std::size_t k = 0; k < r.scenes().size(); ++k) {
    const auto& scene = r.scenes()[k];
    // The server publishes a scene's files again when its settings change at run time (a
    // material, a physics rate): say so, rather than list it as another scene.
    std::size_t changes = 0;
    if (const auto settings = viscera::common::try_parse_json(scene.settings_json); settings && settings->is_object()) {
      const auto c = settings->find("changes");
      if (c != settings->end() && c->is_array()) changes = c->size();
    }
    if (k > 0 && r.scenes()[k - 1].generation == scene.generation) {
      std::printf("  scene (generation %u): its settings changed at run time (%zu change%s so far)\n", scene.generation, changes,
                  changes == 1 ? "" : "s");
      continue;
    }
    std::printf("  scene (generation %u) from tick %llu, %s\n", scene.generation, static_cast<unsigned long long>(scene.first_tick),
                shown(scene.server_version).c_str());
    for (const auto& f : scene.files)
      std::printf("    %s: %s (attachment %s, sha256 %s)\n", shown(f.role).c_str(), shown(f.path).c_str(), shown(f.attachment).c_str(),
                  shown(f.sha256).c_str());
  }
  if (r.drops()) {
    std::printf("  drops: %s missing\n", r.drops()->count("missing") ? shown(r.drops()->at("missing")).c_str() : "?");
    for (const auto& [k, v] : *r.drops())
      if (k != "missing") std::printf("    %s: %s\n", shown(k).c_str(), shown(v).c_str());
  } else {
    std::printf("  drops: not recorded (the recording was recovered after its recorder stopped abruptly)\n");
  }
  if (!verify) return 0;
  const viscera::mcap::Integrity integrity = r.integrity();
  std::printf("  records: %s\n", integrity.intact() ? "every record reads and its CRC holds; the indexes point at them" : "damaged:");
  for (const auto& p : integrity.problems) std::printf("    %s\n", viscera::common::printable(p, 300).c_str());
  std::uint64_t good = 0, bad = 0;
  std::string first_bad;
  try {
    r.for_each([&](const rec::RecordedChannel& ch, const viscera::mcap::Message& m) {
      std::string why;
      if (rec::payload_decodes(ch.stream, m.data, &why)) {
        ++good;
      } else if (++bad == 1) {
        first_bad = std::string(proto::stream_name(ch.stream)) + " message " + std::to_string(m.sequence) + " (log time " +
                    std::to_string(m.log_time) + "): " + why;
      }
      return true;
    });
  } catch (const viscera::common::InputError& e) {  // a damaged chunk, already among the problems
    if (integrity.intact()) throw;
  }
  std::printf("  payloads: %llu decode with viscera's decoders, %llu do not%s%s\n", static_cast<unsigned long long>(good),
              static_cast<unsigned long long>(bad), bad ? "; the first: " : "", viscera::common::printable(first_bad, 300).c_str());
  return bad == 0 && integrity.intact() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl(
      "viscera-record",
      "Records a viscera session to MCAP (docs/RECORDING.md): every stream of the DDS domain and partition (instrument\n"
      "commands, forces, session requests, scene state, telemetry, surface topology and frames, events and annotations),\n"
      "each payload as it was on the wire with its binary FlatBuffers schema, in zstd- or lz4-compressed chunks with\n"
      "indexes, statistics and CRCs; the files the scene was built from as attachments. Counts every writer's lost\n"
      "samples and prints them at the end and in the file. SIGINT/SIGTERM stop it and close the file; killed, the file\n"
      "is readable up to its last chunk (recover).\n"
      "  viscera-record --out FILE.mcap [--duration S] [--topics a,b,...]   record\n"
      "  viscera-record recover IN.mcap OUT.mcap                            a complete, indexed copy of what is there\n"
      "  viscera-record info FILE.mcap [--verify]                           channels, schemas, counts, time span, drops");
  cl.usage("viscera-record --out FILE.mcap [options] | recover IN.mcap OUT.mcap | info FILE.mcap [--verify]");
  cl.flag("out", "FILE.mcap", "the recording to write (a new file: an existing one is refused unless --replace; a symbolic link always)");
  cl.option_switch("replace", "replace the --out file if it exists (never through a symbolic link)");
  cl.flag("duration", "S", "stop after S seconds; 0: until SIGINT/SIGTERM", "0");
  cl.flag("topics", "a,b,...", "streams to record (default: all; names as in docs/PROTOCOL.md, e.g. force_feedback,event)", "");
  cl.flag("domain", "ID", "DDS domain", "0");
  cl.flag("station", "NAME", "the station to record: its DDS partition (default: none, the default partition)", "");
  cl.flag("compression", "NAME", "zstd | lz4 | none", "zstd");
  cl.flag("chunk-mb", "MIB", "close a chunk at this much data [MiB]", "4");
  cl.flag("chunk-s", "S", "or when its messages span this long [s] (the most a killed recorder loses)", "1");
  cl.flag("depth", "N", "samples kept per key between two reads of the recorder (1 kHz streams)", "4096");
  cl.option_switch("quiet", "no status line each second");
  cl.option_switch("verify", "info: also decode every payload with viscera's own decoders (exit 1 if one does not)");
  cl.allow_positional(3);
  try {
    if (!cl.parse(argc, argv)) return 0;
    const auto& args = cl.positional();
    if (!args.empty() && args[0] == "recover") return recover(args);
    if (!args.empty() && args[0] == "info") return info(args, cl.has("verify"));
    if (!args.empty()) throw UsageError("unknown command '" + args[0] + "' (recover, info, or --out FILE to record)");
    return record(cl);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-record: %s\n", e.what());
    return 2;
  } catch (const viscera::common::InputError& e) {
    std::fprintf(stderr, "viscera-record: %s\n", e.what());
    return 2;
  } catch (const proto::DdsError& e) {
    std::fprintf(stderr, "viscera-record: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-record: %s\n", e.what());
    return 1;
  }
}
