// The MCAP writer and reader against the specification's own check values and against each  // SPDX-License-Identifier: Apache-2.0
// other's independent halves: what is written is read back whole (every message, in order, on its
// channel), chunk by chunk through the summary's index as through the data section; a file cut at
// any byte gives exactly the messages of its complete chunks, and recover() makes it whole; a
// damaged byte is found by the CRCs. (The official reader, @mcap/core, judges the files in the
// integration test tests/integration/recording_test.sh.)
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/mcap/compression.hpp"
#include "viscera/mcap/integrity.hpp"
#include "viscera/mcap/mcap_reader.hpp"
#include "viscera/mcap/mcap_writer.hpp"

#include "payload.hpp"

namespace {

using namespace viscera::mcap;
using viscera::mcap::test::payload;
namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() : path(fs::temp_directory_path() / ("viscera-mcap-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++))) {
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
  static int& counter() {
    static int n = 0;
    return n;
  }
};

/// A payload whose bytes depend on (channel, k): any mix-up shows.

struct Written {
  std::vector<Message> messages;  // in the order written
  int chunks_expected_at_least = 0;
};

/// Three channels on two schemas, `n` messages each at 1 kHz of log time, of mixed sizes.
Written write_file(const std::string& path, const std::string& compression, int n, std::size_t chunk_bytes) {
  WriterOptions o;
  o.compression = compression;
  o.chunk_bytes = chunk_bytes;
  o.profile = "test";
  McapWriter w(path, o);
  const auto s1 = w.add_schema("a.A", "flatbuffer", {1, 2, 3});
  const auto s2 = w.add_schema("b.B", "flatbuffer", {4, 5});
  const std::uint16_t ch[3] = {w.add_channel(s1, "/a", "flatbuffer", {{"source_id", "1"}}),
                               w.add_channel(s1, "/a", "flatbuffer", {{"source_id", "2"}}), w.add_channel(s2, "/b", "flatbuffer")};
  Written out;
  std::size_t bytes = 0;
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) {
      Message m{ch[c], static_cast<std::uint32_t>(k), 1'000'000'000ull + 1'000'000ull * static_cast<std::uint64_t>(k),
                777ull + static_cast<std::uint64_t>(k), payload(c, k, 16 + static_cast<std::size_t>((k * 37 + c * 101) % 900))};
      w.add_message(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
      bytes += m.data.size() + 31;
      out.messages.push_back(std::move(m));
    }
  w.add_attachment({5, 6, "scene/liver.json", "application/json", {'{', '}'}});
  w.add_metadata({"viscera.test", {{"k", "v"}, {"n", std::to_string(n)}}});
  w.close();
  out.chunks_expected_at_least = static_cast<int>(bytes / chunk_bytes);
  return out;
}

std::vector<Message> read_all(const std::string& path, DataEnd* end = nullptr) {
  McapReader r(path);
  std::vector<Message> got;
  DataVisitor v;
  v.message = [&](const Message& m) { got.push_back(m); };
  const DataEnd e = r.read_data(v);
  if (end) *end = e;
  return got;
}

void expect_same(const std::vector<Message>& a, const std::vector<Message>& b, std::size_t n) {
  ASSERT_GE(a.size(), n);
  ASSERT_GE(b.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(a[i].channel_id, b[i].channel_id) << i;
    ASSERT_EQ(a[i].sequence, b[i].sequence) << i;
    ASSERT_EQ(a[i].log_time, b[i].log_time) << i;
    ASSERT_EQ(a[i].publish_time, b[i].publish_time) << i;
    ASSERT_EQ(a[i].data, b[i].data) << i;
  }
}

TEST(McapFile, EveryMessageReadsBackInOrderThroughTheDataSectionAndTheChunkIndex) {
  for (const std::string compression : {"zstd", "lz4", ""}) {
    TempDir dir;
    const std::string path = dir.file("a.mcap");
    const Written w = write_file(path, compression, 600, 64 * 1024);
    DataEnd end;
    const auto got = read_all(path, &end);
    EXPECT_TRUE(end.complete) << end.error;
    ASSERT_EQ(got.size(), w.messages.size());
    expect_same(got, w.messages, got.size());

    McapReader r(path);
    EXPECT_EQ(r.profile(), "test");
    const auto s = r.summary();
    ASSERT_TRUE(s) << compression;
    ASSERT_TRUE(s->statistics);
    EXPECT_EQ(s->statistics->message_count, w.messages.size());
    EXPECT_EQ(s->statistics->channel_count, 3u);
    EXPECT_EQ(s->statistics->schema_count, 2);
    EXPECT_EQ(s->statistics->message_start_time, w.messages.front().log_time);
    EXPECT_EQ(s->statistics->message_end_time, w.messages.back().log_time);
    for (const auto& [channel, count] : s->statistics->channel_message_counts) EXPECT_EQ(count, 600u) << channel;
    EXPECT_GE(static_cast<int>(s->chunks.size()), w.chunks_expected_at_least);
    EXPECT_EQ(s->statistics->chunk_count, s->chunks.size());
    ASSERT_EQ(s->channels.size(), 3u);
    EXPECT_EQ(s->channels[1].metadata.at("source_id"), "2");
    // Chunk by chunk through the index: the same messages, each chunk's log times within its bounds.
    std::vector<Message> by_chunk;
    for (const auto& c : s->chunks) {
      EXPECT_EQ(c.compression, compression);
      for (auto& m : r.read_chunk(c)) {
        EXPECT_GE(m.log_time, c.start_time);
        EXPECT_LE(m.log_time, c.end_time);
        by_chunk.push_back(std::move(m));
      }
    }
    ASSERT_EQ(by_chunk.size(), w.messages.size());
    expect_same(by_chunk, w.messages, by_chunk.size());
    ASSERT_EQ(s->attachments.size(), 1u);
    const Attachment a = r.read_attachment(s->attachments[0]);
    EXPECT_EQ(a.name, "scene/liver.json");
    EXPECT_EQ(a.data, (std::vector<std::uint8_t>{'{', '}'}));
    ASSERT_EQ(s->metadata.size(), 1u);
    EXPECT_EQ(r.read_metadata(s->metadata[0]).values.at("n"), "600");
  }
}

TEST(McapFile, AFileCutAtAnyByteGivesTheMessagesOfItsCompleteChunksAndRecoverMakesItWhole) {
  TempDir dir;
  const std::string path = dir.file("whole.mcap");
  const Written w = write_file(path, "zstd", 300, 16 * 1024);
  const auto bytes = viscera::common::read_file_bytes(path);
  McapReader whole(path);
  const auto summary = whole.summary();
  ASSERT_TRUE(summary);
  DataEnd whole_end;
  read_all(path, &whole_end);
  const std::uint64_t data_end = whole_end.offset + 9 + 4;  // Data End: opcode, length, CRC
  // Messages up to the end of each chunk, from the index (independent of read_data).
  std::vector<std::pair<std::uint64_t, std::size_t>> chunk_ends;  // (end offset, messages so far)
  std::size_t so_far = 0;
  for (const auto& c : summary->chunks) {
    so_far += whole.read_chunk(c).size();
    chunk_ends.emplace_back(c.offset + c.length, so_far);
  }
  std::mt19937 rng(7);
  std::vector<std::size_t> cuts = {9,
                                   20,
                                   static_cast<std::size_t>(chunk_ends[0].first),
                                   static_cast<std::size_t>(chunk_ends[0].first) + 1,
                                   static_cast<std::size_t>(data_end) - 1,
                                   static_cast<std::size_t>(data_end),
                                   bytes.size() - 1};
  for (int k = 0; k < 12; ++k) cuts.push_back(std::uniform_int_distribution<std::size_t>(30, bytes.size() - 40)(rng));
  for (const std::size_t cut : cuts) {
    const std::string part = dir.file("cut.mcap");
    viscera::common::write_file_bytes(part, std::span<const std::uint8_t>(bytes).first(cut));
    std::size_t expected = 0;
    for (const auto& [end, n] : chunk_ends)
      if (end <= cut) expected = n;
    if (cut < 8 + 9 + 4) {  // not even a whole header
      EXPECT_THROW(McapReader{part}, viscera::common::InputError);
      continue;
    }
    DataEnd end;
    const auto got = read_all(part, &end);
    if (cut >= data_end) {  // only the summary is cut: the data section is whole
      EXPECT_TRUE(end.complete) << cut;
      expected = w.messages.size();
    } else {
      EXPECT_FALSE(end.complete) << cut;
      EXPECT_FALSE(end.error.empty()) << cut;
    }
    EXPECT_EQ(got.size(), expected) << "cut at byte " << cut;
    expect_same(got, w.messages, got.size());
    EXPECT_FALSE(McapReader(part).summary()) << cut;  // no footer: no summary
    const std::string fixed = dir.file("fixed.mcap");
    fs::remove(fixed);  // the last cut's copy: recover never replaces a file
    const DataEnd r = recover(part, fixed);
    EXPECT_EQ(r.messages, expected);
    DataEnd fixed_end;
    const auto again = read_all(fixed, &fixed_end);
    EXPECT_TRUE(fixed_end.complete) << fixed_end.error;
    ASSERT_EQ(again.size(), expected);
    expect_same(again, w.messages, expected);
    const auto s = McapReader(fixed).summary();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->statistics->message_count, expected);
  }
}

TEST(McapFile, ADamagedByteIsFoundByTheCrcs) {
  TempDir dir;
  const std::string path = dir.file("a.mcap");
  write_file(path, "", 200, 16 * 1024);  // uncompressed: a flipped byte stays a valid stream
  auto bytes = viscera::common::read_file_bytes(path);
  McapReader whole(path);
  const auto summary = whole.summary();
  ASSERT_TRUE(summary && summary->chunks.size() >= 3);
  // A byte in the middle of the second chunk's records.
  const auto& c = summary->chunks[1];
  bytes[static_cast<std::size_t>(c.offset + c.length / 2)] ^= 0x40;
  const std::string damaged = dir.file("damaged.mcap");
  viscera::common::write_file_bytes(damaged, bytes);
  DataEnd end;
  read_all(damaged, &end);
  EXPECT_FALSE(end.complete);
  EXPECT_NE(end.error.find("CRC"), std::string::npos) << end.error;
  EXPECT_EQ(end.chunks, 1u);
  McapReader r(damaged);
  EXPECT_THROW(r.read_chunk(r.summary()->chunks[1]), viscera::common::InputError);
  // A byte of the summary: its CRC.
  auto tail = viscera::common::read_file_bytes(path);
  tail[tail.size() - 40] ^= 0x01;
  const std::string bad_summary = dir.file("bad-summary.mcap");
  viscera::common::write_file_bytes(bad_summary, tail);
  EXPECT_THROW(McapReader(bad_summary).summary(), viscera::common::InputError);
}

TEST(McapFile, NotAnMcapFileIsOneClearErrorNamingTheFile) {
  TempDir dir;
  const std::string path = dir.file("notes.mcap");
  std::ofstream(path) << "these are not the bytes you are looking for";
  try {
    McapReader r(path);
    FAIL() << "accepted";
  } catch (const viscera::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not an MCAP file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(McapReader(dir.path.string()), viscera::common::InputError);  // a directory
  EXPECT_THROW(McapReader(dir.file("missing.mcap")), viscera::common::InputError);
}

/// The messages of the original file's chunks, all but chunk `skip`, in file order (from the index,
/// independent of the walk of the data section).
std::string damage_list(const DataEnd& end) {
  std::string out;
  for (const auto& d : end.damaged) out += "\n  bytes " + std::to_string(d.offset) + " +" + std::to_string(d.length) + ": " + d.what;
  return out;
}

std::vector<Message> all_but_chunk(const std::string& path, std::size_t skip) {
  McapReader r(path);
  const auto s = r.summary();
  std::vector<Message> out;
  for (std::size_t k = 0; k < s->chunks.size(); ++k)
    if (k != skip)
      for (auto& m : r.read_chunk(s->chunks[k])) out.push_back(std::move(m));
  return out;
}

TEST(McapFile, RecoverKeepsEveryIntactChunkAroundADamagedOneAndSaysWhatWasLost) {
  for (const std::string compression : {"", "zstd"}) {
    TempDir dir;
    const std::string path = dir.file("a.mcap");
    write_file(path, compression, 300, 16 * 1024);
    const auto bytes = viscera::common::read_file_bytes(path);
    const auto summary = McapReader(path).summary();
    ASSERT_TRUE(summary && summary->chunks.size() >= 6);
    const auto& c1 = summary->chunks[1];
    const std::vector<Message> want = all_but_chunk(path, 1);
    // A byte inside the chunk's records, and a byte of the chunk's own length (its framing).
    for (const std::uint64_t at : {c1.offset + c1.length / 2, c1.offset + 3}) {
      auto damaged = bytes;
      damaged[static_cast<std::size_t>(at)] ^= 0x40;
      const std::string in = dir.file("damaged.mcap"), out = dir.file("recovered.mcap");
      viscera::common::write_file_bytes(in, damaged);
      fs::remove(out);  // the last byte's copy: recover never replaces a file
      const DataEnd end = recover(in, out);
      EXPECT_FALSE(end.intact()) << at;
      ASSERT_FALSE(end.damaged.empty()) << at;
      EXPECT_EQ(end.damaged.front().offset, c1.offset) << at;
      EXPECT_EQ(end.messages, want.size()) << compression << " byte " << at << damage_list(end);
      const auto got = read_all(out);
      ASSERT_EQ(got.size(), want.size());
      expect_same(got, want, want.size());
      // The one judgement of integrity sees it too.
      McapReader r(in);
      EXPECT_FALSE(check_integrity(r).intact()) << at;
    }
    McapReader whole(path);
    const Integrity fine = check_integrity(whole);
    EXPECT_TRUE(fine.intact()) << (fine.problems.empty() ? "" : fine.problems.front());
  }
}

/// A file of three complete chunks: the bytes of a written file up to where its fourth chunk
/// starts (after the third's message indexes).
std::vector<std::uint8_t> three_chunks(const TempDir& dir) {
  const std::string path = dir.file("a.mcap");
  write_file(path, "zstd", 300, 16 * 1024);
  const auto summary = McapReader(path).summary();
  if (!summary || summary->chunks.size() < 4) throw std::runtime_error("the test file has fewer than four chunks");
  auto bytes = viscera::common::read_file_bytes(path);
  bytes.resize(static_cast<std::size_t>(summary->chunks[3].offset));
  return bytes;
}

TEST(McapFile, AZeroFilledTailEndsTheWalkAtItsFirstByteAtOnce) {
  TempDir dir;
  // Three chunks, then 8 MiB of zeros, as a file system leaves space a crash never wrote.
  auto bytes = three_chunks(dir);
  const std::uint64_t cut = bytes.size();
  bytes.resize(bytes.size() + (8u << 20), 0);
  const std::string in = dir.file("zeros.mcap");
  viscera::common::write_file_bytes(in, bytes);
  const auto t0 = std::chrono::steady_clock::now();
  McapReader r(in);
  const DataEnd end = r.salvage_data({});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_EQ(end.chunks, 3u);
  EXPECT_EQ(end.offset, cut);
  ASSERT_EQ(end.damaged.size(), 1u);
  EXPECT_EQ(end.damaged[0].offset, cut);
  EXPECT_EQ(end.damaged[0].length, 8u << 20);
  EXPECT_NE(end.damaged[0].what.find("zero bytes"), std::string::npos) << end.damaged[0].what;
  // The strict walk stops there too, naming opcode 0, instead of reading zeros as records.
  DataEnd strict;
  read_all(in, &strict);
  EXPECT_EQ(strict.offset, cut);
  EXPECT_NE(strict.error.find("opcode 0"), std::string::npos) << strict.error;
}

TEST(McapFile, AWalkOverMillionsOfSmallRecordsReadsTheFileInBlocks) {
  TempDir dir;
  // After three chunks, 20 MB of records of an opcode this reader does not know (the
  // specification: skip them), 9 bytes each: 2.2 million records. A seek and a read per record
  // took more than 60 s for 50 MB.
  auto bytes = three_chunks(dir);
  constexpr std::size_t kRecords = 20'000'000 / 9;
  for (std::size_t k = 0; k < kRecords; ++k) bytes.insert(bytes.end(), {0x80, 0, 0, 0, 0, 0, 0, 0, 0});
  const std::string in = dir.file("small-records.mcap");
  viscera::common::write_file_bytes(in, bytes);
  const auto t0 = std::chrono::steady_clock::now();
  McapReader r(in);
  const DataEnd end = r.salvage_data({});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("[ figure ] %zu records of 9 bytes walked in %.2f s\n", kRecords, seconds);
  // A seek and a read per record took more than 60 s for 50 MB of them (so more than 24 s for these
  // 20 MB); reading in blocks, 0.24 s in Release, 5.9 s under ASan on a busy machine.
  EXPECT_LT(seconds, 15.0);
  EXPECT_EQ(end.chunks, 3u);
  EXPECT_EQ(end.offset, bytes.size());
}

TEST(McapFile, ADamagedAttachmentOrOneClaimingATerabyteIsNotIntact) {
  TempDir dir;
  const std::string path = dir.file("a.mcap");
  write_file(path, "zstd", 50, 16 * 1024);
  const auto bytes = viscera::common::read_file_bytes(path);
  const auto summary = McapReader(path).summary();
  ASSERT_EQ(summary->attachments.size(), 1u);
  const std::size_t at = static_cast<std::size_t>(summary->attachments[0].offset);
  // The attachment: opcode, length, two times, name, media type, data length, data "{}", CRC.
  const std::string name = "scene/liver.json", media = "application/json";
  const std::size_t data_length_at = at + 9 + 16 + 4 + name.size() + 4 + media.size();
  ASSERT_EQ(bytes[data_length_at], 2);
  ASSERT_EQ(bytes[data_length_at + 8], '{');
  auto flipped = bytes;
  flipped[data_length_at + 9] ^= 0x01;  // '}' -> '|'
  auto huge = bytes;
  huge[data_length_at + 5] = 1;  // 2 + 2^40 bytes
  for (const auto& [label, damaged] : {std::pair{"flipped", flipped}, std::pair{"2^40", huge}}) {
    const std::string in = dir.file(std::string("attachment-") + (label[0] == 'f' ? "flipped" : "huge") + ".mcap");
    viscera::common::write_file_bytes(in, damaged);
    McapReader r(in);
    const Integrity i = check_integrity(r);
    ASSERT_FALSE(i.intact()) << label;
    bool named = false;
    for (const auto& p : i.problems) named = named || p.find("attachment") != std::string::npos || p.find(std::to_string(at)) != std::string::npos;
    EXPECT_TRUE(named) << label << ": " << i.problems.front();
    // Recover keeps every message and says the attachment was lost.
    fs::remove(dir.file("recovered.mcap"));  // the last case's copy: recover never replaces a file
    const DataEnd end = recover(in, dir.file("recovered.mcap"));
    EXPECT_EQ(end.messages, 150u) << label << damage_list(end);
    EXPECT_EQ(end.attachments, 0u) << label;
    ASSERT_EQ(end.damaged.size(), 1u) << label;
    EXPECT_EQ(end.damaged[0].offset, at) << label;
  }
}

// A recording is never lost to the next one, and a link planted at the path is not written through
// (a recorder run as root with --out in a shared folder wrote an MCAP over /etc/passwd that way).
TEST(McapFile, AWriterRefusesALinkAlwaysAndAnExistingFileUnlessToldToReplaceIt) {
  TempDir dir;
  const std::string victim = dir.file("victim.txt"), link = dir.file("link.mcap"), existing = dir.file("old.mcap");
  viscera::common::write_file_bytes(victim, std::vector<std::uint8_t>{'m', 'i', 'n', 'e'});
  fs::create_symlink(victim, link);
  write_file(existing, "", 50, 16 * 1024);
  const auto old_bytes = viscera::common::read_file_bytes(existing);
  for (const bool replace : {false, true}) {
    WriterOptions o;
    o.replace = replace;
    try {
      McapWriter w(link, o);
      ADD_FAILURE() << "wrote through a link, replace " << replace;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("link.mcap: is a symbolic link: not written through"), std::string::npos) << e.what();
    }
    EXPECT_EQ(viscera::common::read_file_bytes(victim), (std::vector<std::uint8_t>{'m', 'i', 'n', 'e'}));
  }
  WriterOptions keep;
  keep.replace = false;
  try {
    McapWriter w(existing, keep);
    ADD_FAILURE() << "replaced an existing recording";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("old.mcap: exists, and is not replaced"), std::string::npos) << e.what();
  }
  EXPECT_EQ(viscera::common::read_file_bytes(existing), old_bytes);
  // A FIFO or a device, even with replace: refused at once, not waited on or written to.
  WriterOptions replace;
  ASSERT_EQ(::mkfifo(dir.file("fifo.mcap").c_str(), 0644), 0);
  for (const std::string& special : {dir.file("fifo.mcap"), std::string("/dev/null")}) {
    try {
      McapWriter w(special, replace);
      ADD_FAILURE() << "wrote to " << special;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("is not a regular file"), std::string::npos) << e.what();
    }
  }
  { McapWriter w(dir.file("new.mcap"), keep); }  // a new name: written
  EXPECT_EQ(read_all(dir.file("new.mcap")).size(), 0u);
  // recover writes its copy to a new file only.
  EXPECT_THROW(recover(existing, dir.file("new.mcap")), std::runtime_error);
  EXPECT_EQ(recover(existing, dir.file("copy.mcap")).messages, read_all(existing).size());
}

TEST(McapFile, RecoverRefusesToWriteOverItsInputByAnyName) {
  TempDir dir;
  const std::string path = dir.file("a.mcap");
  write_file(path, "", 50, 16 * 1024);
  const auto before = viscera::common::read_file_bytes(path);
  fs::create_hard_link(path, dir.file("hard.mcap"));
  fs::create_symlink(path, dir.file("soft.mcap"));
  for (const std::string& out : {path, dir.file("hard.mcap"), dir.file("soft.mcap"), dir.path.string() + "/./a.mcap"}) {
    EXPECT_THROW(recover(path, out), viscera::common::InputError) << out;
    EXPECT_EQ(viscera::common::read_file_bytes(path), before) << out;
  }
}

}  // namespace
