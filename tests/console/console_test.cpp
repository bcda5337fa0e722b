// The console bridge's parts that need no network: the token, browser requests, the outbox of a  // SPDX-License-Identifier: Apache-2.0
// browser, the rate limit, the force decimation and the binary wire format, each against what it
// must do by definition (an independent brute-force reference where there is one).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/console/access_token.hpp"
#include "viscera/console/browser_request.hpp"
#include "viscera/console/console_wire.hpp"
#include "viscera/console/force_decimator.hpp"
#include "viscera/console/foxglove_protocol.hpp"
#include "viscera/console/outbox.hpp"
#include "viscera/console/rate_limit.hpp"
#include "viscera/console/recordings.hpp"

namespace vc = viscera::console;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("viscera_console_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string error_of(const std::string& message) {
  std::string why;
  EXPECT_FALSE(vc::parse_browser_request(message, &why)) << message;
  return why;
}

}  // namespace

TEST(AccessToken, ReadsTheFirstLineAndRefusesShortOrBlankTokens) {
  const std::string token(40, 'a');
  EXPECT_EQ(vc::read_token_file(write_temp("ok", "  " + token + " \nrest\n")), token);
  try {
    vc::read_token_file(write_temp("short", "abc\n"));
    FAIL();
  } catch (const viscera::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("token: has 3 characters (32 to 256"), std::string::npos) << e.what();
  }
  EXPECT_THROW(vc::read_token_file(write_temp("blank", std::string(20, 'a') + " " + std::string(20, 'b'))), viscera::common::InputError);
  EXPECT_THROW(vc::read_token_file("/nonexistent/token"), viscera::common::InputError);
  // Bounded: a long token, a large file, a device that never ends.
  EXPECT_THROW(vc::read_token_file(write_temp("long", std::string(257, 'a') + "\n")), viscera::common::InputError);
  EXPECT_EQ(vc::read_token_file(write_temp("longest", std::string(256, 'a') + "\n")), std::string(256, 'a'));
  EXPECT_THROW(vc::read_token_file(write_temp("large", token + "\n" + std::string(5000, '#'))), viscera::common::InputError);
  EXPECT_THROW(vc::read_token_file("/dev/zero"), viscera::common::InputError);
}

TEST(AccessToken, OnlyTheConsolesOwnOriginOrAnAllowedOneOpensASession) {
  EXPECT_TRUE(vc::origin_allowed("", "127.0.0.1:8080", {}));  // not a browser: the token decides
  EXPECT_TRUE(vc::origin_allowed("http://127.0.0.1:8080", "127.0.0.1:8080", {}));
  EXPECT_TRUE(vc::origin_allowed("https://console.example:443", "console.example:443", {}));
  EXPECT_FALSE(vc::origin_allowed("http://evil.example", "127.0.0.1:8080", {}));
  EXPECT_FALSE(vc::origin_allowed("http://127.0.0.1:8081", "127.0.0.1:8080", {}));  // another port is another origin
  EXPECT_FALSE(vc::origin_allowed("null", "127.0.0.1:8080", {}));
  EXPECT_FALSE(vc::origin_allowed("http://127.0.0.1:8080", "", {}));
  EXPECT_TRUE(vc::origin_allowed("https://proxy.example", "127.0.0.1:8080", {"https://proxy.example"}));
  EXPECT_FALSE(vc::origin_allowed("https://proxy.example.evil", "127.0.0.1:8080", {"https://proxy.example"}));
}

TEST(AccessToken, MatchesExactlyTheToken) {
  const std::string t = "0123456789abcdef0123456789abcdef";
  EXPECT_TRUE(vc::token_matches(t, t));
  EXPECT_FALSE(vc::token_matches("", t));
  EXPECT_FALSE(vc::token_matches(t.substr(0, 31), t));
  EXPECT_FALSE(vc::token_matches(t + "0", t));
  for (std::size_t i = 0; i < t.size(); ++i) {  // one character off anywhere
    std::string g = t;
    g[i] = g[i] == 'x' ? 'y' : 'x';
    EXPECT_FALSE(vc::token_matches(g, t)) << i;
  }
}

TEST(BrowserRequest, AcceptsEachTypeWithItsFields) {
  std::string why;
  const auto m = vc::parse_browser_request(R"({"type":"material","id":4,"youngs-modulus-pa":7000,"shear-q":10})", &why);
  ASSERT_TRUE(m) << why;
  EXPECT_EQ(m->type, vc::RequestType::material);
  EXPECT_EQ(m->id, 4u);
  EXPECT_EQ(m->change.youngs_modulus_pa, 7000.0);
  EXPECT_EQ(m->change.shear_q, 10.0);
  EXPECT_FALSE(m->change.poisson_ratio);
  const auto l = vc::parse_browser_request(R"({"type":"load_scene","scene":"liver-nodule","seed":12})", &why);
  ASSERT_TRUE(l) << why;
  EXPECT_EQ(l->text, "liver-nodule");
  EXPECT_EQ(l->seed, 12u);
  const auto mv = vc::parse_browser_request(R"({"type":"move","instrument":3,"delta_m":[0.002,-0.01,0]})", &why);
  ASSERT_TRUE(mv) << why;
  EXPECT_EQ(mv->instrument, 3u);
  EXPECT_EQ(mv->delta_m[1], -0.01);
  // A material file from the page: its text whole, its name made plain as viscera-control does.
  const auto f = vc::parse_browser_request(R"({"type":"material","file-name":"../my fit (2).json","file-text":"{\"name\": \"x\"}"})", &why);
  ASSERT_TRUE(f) << why;
  EXPECT_EQ(f->change.file_name, "my_fit__2_.json");
  EXPECT_EQ(f->change.file_text, R"({"name": "x"})");
  const auto b = vc::parse_browser_request(R"({"type":"bookmark"})", &why);
  ASSERT_TRUE(b) << why;
  EXPECT_TRUE(b->text.empty());
}

TEST(BrowserRequest, RefusesWithTheFieldAndTheValue) {
  EXPECT_EQ(error_of("{"), "not JSON");
  EXPECT_EQ(error_of(std::string(4000, '[') + std::string(4000, ']')), "not JSON");  // nested deeper than the bound
  EXPECT_EQ(error_of("[]"), "not a JSON object");
  EXPECT_EQ(error_of(R"({"kind":"pause"})"), "type: missing, or not a string");
  EXPECT_EQ(error_of(R"({"type":"pause","scene":"x"})"), "pause: unknown field 'scene'");
  // viscera-control's ranges and words (client/session_limits.hpp).
  EXPECT_EQ(error_of(R"({"type":"material","youngs-modulus-pa":2e9})"), "youngs-modulus-pa: 2e+09 is outside [1, 1e+09]");
  EXPECT_EQ(error_of(R"({"type":"material","poisson-ratio":0.5})"), "poisson-ratio: 0.5 is outside [0, 0.4999]");
  EXPECT_EQ(error_of(R"({"type":"material"})").substr(0, 30), "material: needs file-text or a");
  EXPECT_EQ(error_of(R"({"type":"material","file-text":"{}"})"), "material: file-text and file-name go together");
  EXPECT_EQ(error_of(R"({"type":"material","file-name":"","file-text":"{}"})"), "file-name: \"\" is not a file's name");
  EXPECT_EQ(error_of(R"({"type":"material","file-name":"a.json","file-text":7})"), "file-text: not a string of at most 65536 bytes");
  EXPECT_EQ(error_of(R"({"type":"load_scene","scene":"../x"})"), "SCENE '../x' is not a scene name (letters, digits, '.', '_', '-'; no path)");
  EXPECT_EQ(error_of(R"({"type":"pause","id":-1})"), "id: -1 is not a whole number >= 0");
  EXPECT_EQ(error_of(R"({"type":"take_over"})"), "take_over: instrument missing");
  EXPECT_EQ(error_of(R"({"type":"take_over","instrument":0})"), "instrument: 0 is not an instrument id (a whole number >= 1)");
  EXPECT_EQ(error_of(R"({"type":"move","instrument":1,"delta_m":[0,0,0.05]})"), "delta_m: [0,0,0.05]: each step within +-0.01 m");
  EXPECT_EQ(error_of(R"({"type":"move","instrument":1,"delta_m":[0,0]})"), "delta_m: [0,0] is not [dx, dy, dz] in metres");
  EXPECT_EQ(error_of(R"({"type":"annotate","text":")" + std::string(1025, 'a') + "\"}"), "text: not a string of at most 1024 bytes");
  EXPECT_EQ(error_of(std::string(vc::kMaxRequestBytes + 1, ' ')).substr(0, 11), "request of ");
}

TEST(Outbox, KeepsOnlyTheNewestFrameAndMessagesInOrder) {
  vc::Outbox box(1000);
  const auto msg = [](std::string s, bool droppable) { return vc::OutMessage{std::make_shared<const std::string>(std::move(s)), false, droppable}; };
  for (int i = 0; i < 5; ++i) box.put_frame(std::make_shared<const std::string>("frame" + std::to_string(i)));
  EXPECT_TRUE(box.put(msg("a", false)));
  EXPECT_TRUE(box.put(msg("b", true)));
  EXPECT_EQ(box.frames_skipped(), 4u);
  EXPECT_EQ(*box.take()->data, "a");
  EXPECT_EQ(*box.take()->data, "b");
  const auto f = box.take();
  EXPECT_TRUE(f->binary);
  EXPECT_EQ(*f->data, "frame4");
  EXPECT_FALSE(box.take());
}

TEST(Outbox, DropsTheOldestDroppableFirstAndRefusesWhatCannotFit) {
  vc::Outbox box(100);
  const auto msg = [](char c, std::size_t n, bool droppable) { return vc::OutMessage{std::make_shared<const std::string>(n, c), false, droppable}; };
  EXPECT_TRUE(box.put(msg('a', 40, true)));
  EXPECT_TRUE(box.put(msg('e', 30, false)));
  EXPECT_TRUE(box.put(msg('b', 20, true)));
  EXPECT_TRUE(box.put(msg('f', 40, false)));  // 130 > 100: the oldest droppable ('a') goes
  EXPECT_EQ(box.messages_dropped(), 1u);
  EXPECT_EQ(box.queued_bytes(), 90u);
  EXPECT_FALSE(box.put(msg('g', 50, false)));  // 'b' dropped, still 70 + 50 > 100: too slow
  EXPECT_LE(box.queued_bytes(), 100u);
  std::string order;
  while (auto m = box.take()) order += m->data->front();
  EXPECT_EQ(order, "ef");
}

TEST(RateLimit, PassesTheRateOnAverageAndTheBurstAtOnce) {
  vc::RateLimit limit(20, 40);
  int passed = 0;
  for (int i = 0; i < 100; ++i) passed += limit.allow(0.0);
  EXPECT_EQ(passed, 40);  // the burst
  passed = 0;
  for (int k = 1; k <= 10000; ++k) passed += limit.allow(k * 1e-3);  // 10 s at 1 kHz
  EXPECT_NEAR(passed, 200, 1);  // 20 a second
}

TEST(ForceDecimator, KeepsEachPeriodsPeakAgainstBruteForce) {
  // A 1 kHz force with a one-sample spike in some periods; the summaries' peaks must equal the
  // largest magnitude among the samples each one covers.
  vc::ForceDecimator d(1.0 / 30);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> pending;
  std::vector<std::pair<double, double>> checked;  // (summary peak, brute-force peak)
  for (int k = 0; k < 3000; ++k) {
    viscera::protocol::Force f;
    f.instrument_id = 1;
    f.server_stamp_ns = static_cast<std::int64_t>(k) * 1'000'000;
    f.force = {u(rng), u(rng), (k % 97 == 0) ? 25.0 : u(rng)};
    d.add(f);
    pending.push_back(std::hypot(f.force[0], f.force[1], f.force[2]));
    for (const auto& s : d.flush(1e-3 * (k + 1))) {
      EXPECT_EQ(s.samples, pending.size());
      checked.emplace_back(s.peak_n, *std::max_element(pending.begin(), pending.end()));
      pending.clear();
    }
  }
  ASSERT_GT(checked.size(), 80u);  // about 30 a second over 3 s
  int spikes = 0;
  for (const auto& [got, want] : checked) {
    EXPECT_EQ(got, want);
    spikes += want >= 25.0;
  }
  EXPECT_GE(spikes, 30);  // every spike kept (31 in 3000 samples)
}

TEST(ConsoleWire, BinaryMessagesDecodeAsThePageReadsThem) {
  viscera::protocol::SurfaceTopology t;
  t.mesh_id = 7;
  t.vertex_count = 3;
  t.rest_positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  t.triangles = {0, 1, 2};
  const std::string top = vc::encode_topology(t);
  ASSERT_EQ(top.size(), vc::kTopologyHeaderBytes + 4 * 9 + 4 * 3);
  std::uint32_t u[3];
  std::memcpy(u, top.data() + 4, 12);
  EXPECT_EQ(top[0], 1);
  EXPECT_EQ(u[0], 7u);
  EXPECT_EQ(u[1], 3u);
  EXPECT_EQ(u[2], 1u);
  float p;
  std::memcpy(&p, top.data() + vc::kTopologyHeaderBytes + 4 * 3, 4);  // vertex 1, x
  EXPECT_EQ(p, 1.0f);
  std::uint32_t last;
  std::memcpy(&last, top.data() + top.size() - 4, 4);
  EXPECT_EQ(last, 2u);

  viscera::protocol::MeshFrame m;
  m.mesh_id = 7;
  m.frame = 42;
  m.sim_time_s = 1.5;
  m.positions = {0, 0, 0.5f, 1, 0, 0, 0, 1, 0};
  const std::string fr = vc::encode_frame(m, 1.7e12);
  ASSERT_EQ(fr.size(), vc::kFrameHeaderBytes + 4 * 9);
  double d[3];
  std::memcpy(d, fr.data() + 16, 24);
  EXPECT_EQ(d[0], 42.0);
  EXPECT_EQ(d[1], 1.5);
  EXPECT_EQ(d[2], 1.7e12);
  std::memcpy(&p, fr.data() + vc::kFrameHeaderBytes + 8, 4);
  EXPECT_EQ(p, 0.5f);
  EXPECT_EQ(vc::kFrameHeaderBytes % 4, 0u);  // the page's Float32Array view must be aligned
}

TEST(Foxglove, Base64MatchesTheRfc4648Vectors) {
  const auto b64 = [](std::string s) { return vc::base64({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}); };
  EXPECT_EQ(b64(""), "");
  EXPECT_EQ(b64("f"), "Zg==");
  EXPECT_EQ(b64("fo"), "Zm8=");
  EXPECT_EQ(b64("foo"), "Zm9v");
  EXPECT_EQ(b64("foob"), "Zm9vYg==");
  EXPECT_EQ(b64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(b64("foobar"), "Zm9vYmFy");
}

TEST(Foxglove, MessageDataIsOpcodeSubscriptionTimeAndPayload) {
  const std::vector<std::uint8_t> payload = {9, 8, 7};
  const std::string m = vc::foxglove_message_data(0x01020304, 0x1122334455667788ULL, payload);
  ASSERT_EQ(m.size(), 16u);
  EXPECT_EQ(m[0], 1);
  EXPECT_EQ(static_cast<std::uint8_t>(m[1]), 0x04);  // little-endian
  EXPECT_EQ(static_cast<std::uint8_t>(m[5]), 0x88);
  EXPECT_EQ(static_cast<std::uint8_t>(m[12]), 0x11);
  EXPECT_EQ(m[13], 9);
  EXPECT_EQ(m[15], 7);
}

TEST(Foxglove, SubscriptionsAreCheckedAndRouted) {
  vc::FoxgloveSubscriptions s;
  const auto force = vc::foxglove_channel(viscera::protocol::Stream::force_feedback);
  EXPECT_FALSE(s.apply(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":)" + std::to_string(force) + "}]}"));
  EXPECT_EQ(s.to(force), std::vector<std::uint32_t>{5});
  EXPECT_EQ(*s.apply(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":1}]})"), "subscribe: subscription id 5 is in use");
  EXPECT_EQ(*s.apply(R"({"op":"subscribe","subscriptions":[{"id":6,"channelId":999}]})"), "subscribe: no channel 999");
  EXPECT_EQ(*s.apply(R"({"op":"advertise"})"), "op 'advertise' is not supported (subscribe, unsubscribe)");
  EXPECT_TRUE(s.apply("nonsense"));
  EXPECT_FALSE(s.apply(R"({"op":"unsubscribe","subscriptionIds":[5]})"));
  EXPECT_FALSE(s.any());
  // Every advertised channel carries its stream's topic and a schema.
  const auto adv = vc::foxglove_advertise();
  EXPECT_EQ(adv["channels"].size(), vc::foxglove_streams().size());
  for (const auto& c : adv["channels"]) EXPECT_GT(c["schema"].get<std::string>().size(), 100u) << c["topic"];
}

TEST(Recordings, OnlyPlainMcapNamesOfTheFolderAreOffered) {
  EXPECT_TRUE(vc::is_recording_name("session-1.mcap"));
  EXPECT_FALSE(vc::is_recording_name("../session.mcap"));
  EXPECT_FALSE(vc::is_recording_name(".hidden.mcap"));
  EXPECT_FALSE(vc::is_recording_name("session.json"));
  EXPECT_FALSE(vc::is_recording_name(".mcap"));
  const auto dir = std::filesystem::temp_directory_path() / "viscera_console_recordings";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "sub.mcap");  // a folder, not a recording
  for (const char* name : {"b.mcap", "a.mcap", "notes.txt", "with space.mcap"}) std::ofstream(dir / name) << "x";
  EXPECT_EQ(vc::list_recordings(dir.string()), (std::vector<std::string>{"a.mcap", "b.mcap"}));
  EXPECT_TRUE(vc::list_recordings("").empty());
  EXPECT_TRUE(vc::list_recordings((dir / "absent").string()).empty());
  std::string why;
  EXPECT_FALSE(vc::parse_browser_request(R"({"type":"open_recording","file":"../x.mcap"})", &why));
  EXPECT_EQ(why, "file: \"../x.mcap\" is not a recording's name (letters, digits, '.', '_', '-', ending in .mcap; no path)");
  const auto ok = vc::parse_browser_request(R"({"type":"open_recording","file":"a.mcap"})", &why);
  ASSERT_TRUE(ok) << why;
  EXPECT_EQ(ok->text, "a.mcap");
}
