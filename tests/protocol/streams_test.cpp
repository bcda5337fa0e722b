// The table of streams (protocol/streams.hpp) against what the rest of the protocol says of each  // SPDX-License-Identifier: Apache-2.0
// stream: its topic and name, its binary schema, its decoder; and the typed reader over a real
// DDS domain in this process, which hands over what decodes and counts, with a reason, what does not.
#include "viscera/protocol/streams.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "viscera/protocol/binary_schemas.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/typed_reader.hpp"

using namespace viscera::protocol;

namespace {
Stream at(int k) { return static_cast<Stream>(k); }
}  // namespace

TEST(Streams, EveryStreamHasOneRowUnderItsOwnTopicAndName) {
  for (int k = 0; k < kStreamCount; ++k) {
    const StreamInfo& info = stream_info(at(k));
    EXPECT_EQ(info.stream, at(k));
    EXPECT_EQ(std::string(info.topic), std::string("viscera_") + stream_name(at(k)));
    Stream parsed{};
    ASSERT_TRUE(parse_stream(stream_name(at(k)), &parsed)) << info.topic;
    EXPECT_EQ(parsed, at(k));
  }
}

TEST(Streams, EachBinarySchemaDefinesTheRootTableTheTableNames) {
  for (const StreamInfo& info : streams()) {
    const BinarySchema b = binary_schema(info.stream);
    EXPECT_EQ(b.name, std::string("viscera.wire.") + info.schema);
    // The reflection data hold every table's fully qualified name as a string.
    const std::string bytes(b.bfbs.begin(), b.bfbs.end());
    EXPECT_NE(bytes.find(b.name), std::string::npos) << info.topic << " has no table " << b.name << " in " << info.schema_file << ".bfbs";
  }
}

TEST(Streams, StateIsWhatLateJoinersGetAndDroppableIsWhatIsNotRetransmittedOrKeptAll) {
  for (const StreamInfo& info : streams()) {
    EXPECT_EQ(info.state, info.durability == Durability::transient_local) << info.topic;
    if (info.reliability == Reliability::best_effort) {
      EXPECT_TRUE(info.droppable) << info.topic;
    }
    if (info.droppable) {
      EXPECT_EQ(info.depth, 1) << info.topic;
    }
    if (!info.session) {
      EXPECT_EQ(info.depth, 0) << info.topic << ": a re-simulation's streams lose nothing";
    }
  }
}

TEST(Streams, EachVerifierTakesItsOwnMessageAndRefusesGarbage) {
  Command c;
  c.instrument_id = 1;
  c.client_id = 7;
  c.seq = 1;
  Force f;
  f.instrument_id = 1;
  f.client_id = 7;
  Scene s;
  s.name = "liver";
  s.physics_rate_hz = 1000;
  Event e;
  e.text = "annotation";
  const std::vector<std::pair<Stream, std::vector<std::uint8_t>>> own{{Stream::instrument_command, encode(c)},
                                                                      {Stream::force_feedback, encode(f)},
                                                                      {Stream::session_request, encode(SessionRequest{7, Action::pause, 0})},
                                                                      {Stream::scene_state, encode(s)},
                                                                      {Stream::event, encode(e)}};
  for (const auto& [stream, payload] : own) {
    std::string why;
    EXPECT_TRUE(stream_info(stream).verify(payload, &why)) << stream_name(stream) << ": " << why;
  }
  const std::vector<std::uint8_t> garbage(40, 0xAB);
  for (const StreamInfo& info : streams()) {
    std::string why;
    EXPECT_FALSE(info.verify(garbage, &why)) << info.topic;
    EXPECT_FALSE(why.empty()) << info.topic;
  }
}

TEST(Streams, ATypedReaderHandsOverWhatDecodesAndCountsWhatDoesNotWithTheReason) {
  std::mt19937 rng(std::random_device{}());
  const auto domain = static_cast<std::uint32_t>(100 + rng() % 100);
  Participant p(domain, "streams-test-" + std::to_string(rng()));
  TypedReader<Stream::force_feedback> reader(p);
  Writer writer(p, Stream::force_feedback);
  ASSERT_TRUE(writer.wait_for_readers(std::chrono::seconds(5)));
  Force f;
  f.instrument_id = 3;
  f.client_id = 9;
  f.force = {0, 0, 1.5};
  Rejections rejected;
  std::vector<Force> got;
  const auto take = [&] { reader.take([&](Force m, const Received&) { got.push_back(m); }, rejected); };
  writer.write(3, encode(f));
  for (int i = 0; i < 200 && got.empty(); ++i, take()) reader.wait(std::chrono::milliseconds(10));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].force[2], 1.5);
  const std::vector<std::uint8_t> garbage(40, 0xAB);
  writer.write(3, garbage);
  for (int i = 0; i < 200 && rejected.count == 0; ++i, take()) reader.wait(std::chrono::milliseconds(10));
  EXPECT_EQ(rejected.count, 1u);
  EXPECT_EQ(got.size(), 1u);
  EXPECT_EQ(rejected.last_reason.rfind("force_feedback: ", 0), 0u) << rejected.last_reason;
  EXPECT_GT(rejected.last_reason.size(), std::string("force_feedback: ").size()) << "no reason given";
}

// Whether CYCLONEDDS_URI configures DDS Security (client ids are then bound to certificates): in
// files and inline XML, not in comments; a configuration file that is a FIFO or missing is passed
// over at once (Cyclone names it), never read without end.
TEST(SecurityConfigured, ReadsTheConfigurationsFilesAndInlineXmlButNotComments) {
  const char* before = std::getenv("CYCLONEDDS_URI");
  const std::string saved = before ? before : "";
  const std::string dir = ::testing::TempDir();
  const std::string loopback = std::string("file://") + VISCERA_SOURCE_DIR + "/deploy/dds/loopback.xml";
  const std::string secure = std::string("file://") + VISCERA_SOURCE_DIR + "/deploy/dds/secure.xml";
  const auto with = [](const std::string& uri) {
    ::setenv("CYCLONEDDS_URI", uri.c_str(), 1);
    return security_configured();
  };
  EXPECT_FALSE(with(loopback));
  EXPECT_TRUE(with(loopback + "," + secure)) << "deploy/dds/secure.xml holds <Security>";
  EXPECT_TRUE(with("<CycloneDDS><Domain><SECURITY><Authentication/></SECURITY></Domain></CycloneDDS>")) << "names are not case-sensitive";
  EXPECT_FALSE(with("<CycloneDDS><Domain><!-- <Security> one day --></Domain></CycloneDDS>"));
  EXPECT_FALSE(with("<CycloneDDS><!-- an unclosed comment <Security>"));
  EXPECT_FALSE(with("file://" + dir + "/no-such-config.xml"));
  const std::string fifo = dir + "/viscera-config-fifo";
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_FALSE(with("file://" + fifo)) << "passed over, not read";
  ::unlink(fifo.c_str());
  ::unsetenv("CYCLONEDDS_URI");
  EXPECT_FALSE(security_configured());
  if (before) ::setenv("CYCLONEDDS_URI", saved.c_str(), 1);
}
