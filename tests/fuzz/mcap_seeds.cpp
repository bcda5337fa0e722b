// Writes small, valid MCAP files into a directory, the seeds from which readers_fuzz mutates  // SPDX-License-Identifier: Apache-2.0
// session recordings: each compression (zstd, lz4, none), several chunks, two channels, an
// attachment and metadata, and one file cut short in its data section as a crash leaves it.
// Usage: mcap_seeds DIR
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "viscera/mcap/mcap_writer.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: mcap_seeds DIR\n");
    return 2;
  }
  namespace fs = std::filesystem;
  namespace mcap = viscera::mcap;
  const fs::path dir = argv[1];
  fs::create_directories(dir);
  for (const std::string compression : {"zstd", "lz4", ""}) {
    const auto path = dir / ("session-" + (compression.empty() ? std::string("none") : compression) + ".mcap");
    mcap::WriterOptions options;
    options.compression = compression;
    options.chunk_bytes = 256;
    mcap::McapWriter w(path.string(), options);
    w.add_metadata({"viscera.recording", {{"schema_version", "7"}, {"domain_id", "0"}}});
    const auto schema = w.add_schema("viscera.wire.ForceFeedback", "flatbuffer", {1, 2, 3, 4, 5, 6, 7, 8});
    const auto forces = w.add_channel(schema, "viscera_force_feedback", "flatbuffer", {{"stream", "force_feedback"}, {"writer", "1"}});
    const auto events = w.add_channel(0, "viscera_event", "flatbuffer", {{"stream", "event"}});
    w.add_attachment({1000, 1000, "mesh/cube.msh", "application/octet-stream", {'$', 'M', 'e', 's', 'h'}});
    for (std::uint32_t i = 1; i <= 40; ++i) {
      const std::vector<std::uint8_t> payload(16 + i % 7, static_cast<std::uint8_t>(i));
      w.add_message(i % 5 == 0 ? events : forces, i, 1'000'000ull * i, 1'000'000ull * i - 10, payload);
    }
    w.add_metadata({"viscera.drops", {{"missing", "0"}}});
    w.close();
    if (compression == "zstd") {  // the same, cut short
      const auto cut = dir / "session-cut.mcap";
      fs::copy_file(path, cut, fs::copy_options::overwrite_existing);
      fs::resize_file(cut, fs::file_size(path) / 2);
    }
  }
  return 0;
}
