// The trainer's scoring without a network: synthetic sessions whose metrics are known in closed  // SPDX-License-Identifier: Apache-2.0
// form (hold times, time above a limit, path length, the mark's distance to a sphere), fed as the
// payloads a session's streams carry; the same numbers whatever the arrival order; exercise files
// whose errors name the file and the field.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/training/exercise_scorer.hpp"

using namespace viscera::training;
namespace proto = viscera::protocol;

namespace {

struct Payload {
  proto::Stream stream;
  std::vector<std::uint8_t> bytes;
};

constexpr double kTipRadius = 0.005;

/// A session at 1 kHz: the scene loaded at tick 100, then one command and its force per tick.
struct Session {
  std::vector<Payload> payloads;
  std::uint64_t seq = 0;
  std::uint32_t instrument = 1;

  explicit Session(const std::string& scene, std::vector<proto::RegionInfo> regions = {}) {
    proto::Scene s;
    s.name = scene;
    s.bounds_min = {-0.1, -0.05, -0.05};
    s.bounds_max = {0.1, 0.05, 0.04};  // the top's centre: (0, 0, 0.04)
    s.physics_rate_hz = 1000;
    s.regions = std::move(regions);
    payloads.push_back({proto::Stream::scene_state, proto::encode(s)});
    event(proto::EventKind::scene_loaded, 100, "loaded scene " + scene + " (explicit step 0.0004 s)");
  }
  void event(proto::EventKind kind, std::uint64_t tick, std::string text = {}) {
    proto::Event e;
    e.kind = kind;
    e.tick = tick;
    e.instrument_id = instrument;
    e.text = std::move(text);
    payloads.push_back({proto::Stream::event, proto::encode(e)});
  }
  double tip_strain = 0.05;  ///< every force in contact carries it (Force.tip_strain)
  /// `cutting`: the server says the scalpel's blade cuts (its button held, or pressed through).
  /// `cut_strain`: the strain where the blade cut that tick (Force.cut_edge_strain).
  void step(std::uint64_t tick, const proto::Vector3& tip, double force_n, double strain = 0.1, std::uint32_t buttons = 0, bool cutting = false,
            double cut_strain = 0) {
    proto::Command c;
    c.instrument_id = instrument;
    c.client_id = 7;
    c.seq = ++seq;
    c.tip_position = tip;
    c.buttons = buttons;
    payloads.push_back({proto::Stream::instrument_command, proto::encode(c)});
    proto::Force f;
    f.instrument_id = instrument;
    f.client_id = 7;
    f.command_seq = c.seq;
    f.force = {0, 0, force_n};
    f.in_contact = force_n > 0;
    f.contact_point = {tip[0], tip[1], tip[2] - kTipRadius};  // the tool's sphere touches the tissue below its centre
    f.tick = tick;
    f.max_edge_strain = strain;
    f.tip_strain = f.in_contact ? tip_strain : 0.0;
    f.cutting = cutting;
    f.cut_edge_strain = cut_strain;
    payloads.push_back({proto::Stream::force_feedback, proto::encode(f)});
  }
  ScoreReport score(const Exercise& e, const std::vector<Payload>& order) const {
    ExerciseScorer s(e);
    for (const auto& p : order) s.take(p.stream, p.bytes);
    s.finish();
    return s.report();
  }
  ScoreReport score(const Exercise& e) const { return score(e, payloads); }
};

Exercise drill() {
  return parse_exercise(R"({"name": "drill", "kind": "force_drill", "scene": "liver", "time_limit_s": 60,
    "limits": {"peak_force_n": 2.0, "edge_strain": 0.5}, "force_drill": {"force_n": 1.0, "tolerance_n": 0.1, "hold_s": 10}})",
                        "drill.json");
}

bool has_failure(const ScoreReport& r, const std::string& words) {
  return std::any_of(r.failures.begin(), r.failures.end(), [&](const std::string& f) { return f.find(words) != std::string::npos; });
}

}  // namespace

// A ramp to 1 N over 2 s, then 1 N held: the hold starts at the first tick inside the band
// (0.9 N, 1.8 s after the start) and completes 10 s later; the tip moved 3 mm down during the
// ramp and 1 mm sideways in 1 um steps later: path 4 mm. A 40-tick spike above the limit in a
// second performance: 0.040 s above it, failed for too much force, and the hold restarts after it.
TEST(ExerciseScorer, ForceDrillHoldTimeAboveLimitAndPathAsTheirDefinitions) {
  Session good("liver");
  for (std::uint64_t k = 0; k <= 20000; ++k) {
    const double t = 1e-3 * static_cast<double>(k);
    const double F = t < 2.0 ? 0.5 * t : 1.0;
    const double z = t < 2.0 ? -0.0015 * t : -0.003;
    const double y = k >= 5000 && k < 6000 ? 1e-6 * static_cast<double>(k - 5000 + 1) : k >= 6000 ? 1e-3 : 0.0;
    good.step(100 + k, {0, y, z}, F);
  }
  const ScoreReport r = good.score(drill());
  EXPECT_TRUE(r.started);
  EXPECT_TRUE(r.completed);
  EXPECT_TRUE(r.passed) << (r.failures.empty() ? "" : r.failures[0]);
  EXPECT_EQ(r.start_tick, 100u);
  EXPECT_EQ(r.end_tick, 100u + 1800u + 10000u);  // the first tick at 0.9 N is 1.8 s in
  EXPECT_NEAR(r.time_s, 11.8, 1e-9);
  EXPECT_NEAR(r.longest_hold_s, 10.0, 1e-9);
  EXPECT_NEAR(r.path_length_m, 0.003 + 0.001, 1e-9);
  EXPECT_DOUBLE_EQ(r.peak_force_n, 1.0);
  EXPECT_EQ(r.time_above_force_limit_s, 0.0);
  EXPECT_NEAR(r.max_edge_strain, 0.1, 1e-12);

  Session spiky("liver");
  for (std::uint64_t k = 0; k <= 30000; ++k) {
    const double t = 1e-3 * static_cast<double>(k);
    const bool spike = k >= 5000 && k < 5040;
    spiky.step(100 + k, {0, 0, 0}, spike ? 2.5 : t < 2.0 ? 0.5 * t : 1.0);
  }
  const ScoreReport s = spiky.score(drill());
  EXPECT_FALSE(s.passed);
  EXPECT_NEAR(s.time_above_force_limit_s, 0.040, 1e-12);
  EXPECT_DOUBLE_EQ(s.peak_force_n, 2.5);
  EXPECT_TRUE(has_failure(s, "too much force: 2.50 N"));
  EXPECT_EQ(s.end_tick, 100u + 5040u + 10000u);  // the hold restarted after the spike
  EXPECT_TRUE(s.completed);

  // Never inside the band: not completed, out of time after the limit, failed for it.
  Session weak("liver");
  for (std::uint64_t k = 0; k <= 70000; ++k) weak.step(100 + k, {0, 0, 0}, 0.5);
  const ScoreReport w = weak.score(drill());
  EXPECT_FALSE(w.completed);
  EXPECT_EQ(w.ending, "out of time");
  EXPECT_EQ(w.end_tick, 100u + 60000u);
  EXPECT_TRUE(has_failure(w, "not completed: out of time"));
}

// The same numbers whatever order the payloads arrive in (a tap or a recorder may take forces
// before the commands they answer, and streams in any interleaving).
TEST(ExerciseScorer, TheScoreDoesNotDependOnTheArrivalOrder) {
  Session session("liver");
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, 1e-4);
  for (std::uint64_t k = 0; k <= 15000; ++k) session.step(100 + k, {n(rng), n(rng), n(rng)}, 1.0 + 0.2 * std::sin(1e-3 * static_cast<double>(k)));
  const ScoreReport in_order = session.score(drill());
  std::vector<Payload> shuffled = session.payloads;
  // Forces before commands within blocks of 50 payloads, and the blocks' streams swapped.
  for (std::size_t b = 2; b + 50 < shuffled.size(); b += 50)
    std::shuffle(shuffled.begin() + static_cast<long>(b), shuffled.begin() + static_cast<long>(b + 50), rng);
  const ScoreReport mixed = session.score(drill(), shuffled);
  EXPECT_EQ(to_json(in_order), to_json(mixed));
  EXPECT_GT(in_order.path_length_m, 0.1);
}

// Retraction: the lift is the tip's height above where it grasped; a let-go before the hold is
// complete is a drop, named as such.
TEST(ExerciseScorer, RetractionHoldsTheLiftAndNamesADrop) {
  const Exercise e = parse_exercise(R"({"name": "retraction", "kind": "retraction", "scene": "liver", "instrument": 3, "time_limit_s": 60,
    "retraction": {"lift_m": 0.02, "tolerance_m": 0.005, "hold_s": 5}})",
                                    "retraction.json");
  const auto performance = [](double release_after_s) {
    Session s("liver");
    s.instrument = 3;
    for (std::uint64_t k = 0; k <= 12000; ++k) {
      const double t = 1e-3 * static_cast<double>(k);
      if (k == 500) s.event(proto::EventKind::grasped, 100 + k);
      if (k == static_cast<std::uint64_t>(1000 * (2.5 + release_after_s))) s.event(proto::EventKind::let_go, 100 + k);
      const double lift = t < 0.5 ? 0.0 : std::min(0.02, 0.011 * (t - 0.5));  // 11 mm/s from the grasp, 2 cm up at 2.32 s
      s.step(100 + k, {0, 0, 0.05 + lift}, 0.5);
    }
    return s;
  };
  const ScoreReport good = performance(8.0).score(e);
  EXPECT_TRUE(good.passed) << (good.failures.empty() ? "" : good.failures[0]);
  EXPECT_EQ(good.drops, 0u);
  // Inside the band from a lift of 15 mm, 0.015 / 0.011 = 1.3636 s after the grasp: the first tick
  // at or beyond it is 1.864 s in; held for 5 s from there.
  EXPECT_EQ(good.end_tick, 100u + 1864u + 5000u);
  const ScoreReport dropped = performance(1.0).score(e);
  EXPECT_FALSE(dropped.passed);
  EXPECT_EQ(dropped.drops, 1u);
  EXPECT_TRUE(has_failure(dropped, "the lobe was dropped"));
  EXPECT_NEAR(dropped.longest_hold_s, 3.499 - 1.864, 1e-9);  // from 1.864 s to the last tick before the let-go at 3.5 s
}

// Palpation: the mark is where the tool touched the tissue when button 1 went down (the contact
// point, a tip radius below the tip's centre); its distance to the nodule's surface is
// |mark - centre| - radius (0 inside), scored against the tolerance.
TEST(ExerciseScorer, PalpationScoresTheMarksDistanceToTheNodulesSurface) {
  const Exercise e = parse_exercise(R"({"name": "palpation", "kind": "palpation", "scene": "liver-nodule", "palpation": {"mark_tolerance_m": 0.01}})",
                                    "palpation.json");
  proto::RegionInfo nodule;
  nodule.name = "nodule";
  nodule.center = {0.01, 0.02, 0.0};
  nodule.radius_m = 0.012;
  for (const double dx : {0.0, 0.015, 0.03}) {
    Session s("liver-nodule", {nodule});
    for (std::uint64_t k = 0; k <= 3000; ++k) s.step(100 + k, {0.01 + dx, 0.02, 0.02}, 0.3, 0.1, k >= 2000 && k < 2030 ? kMarkButton : 0);
    const ScoreReport r = s.score(e);
    ASSERT_TRUE(r.mark_distance_m);
    const double expected = std::max(0.0, std::hypot(dx, 0.02 - kTipRadius) - 0.012);
    EXPECT_NEAR(*r.mark_distance_m, expected, 1e-12);
    EXPECT_EQ(r.end_tick, 2100u);
    EXPECT_EQ(r.passed, expected <= 0.01) << "dx " << dx;
    if (!r.passed) {
      EXPECT_TRUE(has_failure(r, "the wrong place was marked"));
    }
  }
  // No mark at all, and a session whose scene never loads.
  Session none("liver-nodule", {nodule});
  for (std::uint64_t k = 0; k <= 3000; ++k) none.step(100 + k, {0, 0, 0}, 0.3);
  EXPECT_TRUE(has_failure(none.score(e), "no place was marked"));
  Session other("liver");
  EXPECT_TRUE(has_failure(other.score(e), "never started: no loading of scene liver-nodule"));
}

TEST(ExerciseFile, ErrorsNameTheFileAndTheField) {
  const auto message = [](const std::string& text) {
    try {
      parse_exercise(text, "ex.json");
    } catch (const viscera::common::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = R"({"name": "x", "scene": "liver", )";
  EXPECT_NE(message(head + R"("kind": "force_drill", "colour": 1})").find("ex.json: colour: unknown field"), std::string::npos);
  EXPECT_NE(message(head + R"("kind": "suturing"})").find("ex.json: kind"), std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "time_limit_s": -3})").find("ex.json: time_limit_s"), std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "limits": {"peak_force_n": 1e9}})").find("ex.json: limits.peak_force_n"), std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "limits": {"tip_strain": 9}})").find("ex.json: limits.tip_strain"), std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "limits": {"tip_strain": "high"}})").find("ex.json: limits.tip_strain"), std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "palpation": {}})").find("ex.json: palpation: belongs to a palpation exercise"),
            std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "force_drill": {"force_n": 1, "tolerance_n": 2}})").find("ex.json: force_drill.tolerance_n"),
            std::string::npos);
  EXPECT_NE(message(head + R"("kind": "force_drill", "limits": {"peak_force_n": 1.0}, "force_drill": {"force_n": 1.0, "tolerance_n": 0.1}})")
                .find("force_drill.force_n"),
            std::string::npos);
  // Names become paths (the report's files, the server's scene): plain names only, named at once.
  EXPECT_NE(message(R"({"name": "x", "kind": "palpation", "scene": "../../etc/passwd"})").find("ex.json: scene: '../../etc/passwd' is not a scene"),
            std::string::npos);
  EXPECT_NE(message(R"({"name": "../../escaped", "kind": "palpation", "scene": "liver"})").find("ex.json: name: '../../escaped' is not a plain name"),
            std::string::npos);
  EXPECT_NE(message("{\"name\": \"a\\u0000b\", \"kind\": \"palpation\", \"scene\": \"liver\"}").find("ex.json: name: 'a\\x00b'"), std::string::npos);
  EXPECT_NE(message("{\"name\": \"\\u001b[2J\", \"kind\": \"palpation\", \"scene\": \"liver\"}").find("ex.json: name: '\\x1B[2J'"),
            std::string::npos);
  EXPECT_NE(message(std::string(100000, '[') + std::string(100000, ']')).find("nested deeper than 64 levels"), std::string::npos);
  for (const char* f : {"palpation.json", "palpation-12k.json", "retraction.json", "force-drill.json", "incision.json"})
    EXPECT_NO_THROW(read_exercise_file(std::string(VISCERA_DATA_DIR) + "/exercises/" + f)) << f;
}

// The strain limits: a file that sets none is scored on the strain at the instrument (the forces'
// tip_strain) against 0.4, and not on the organ's largest edge strain, which grows as a mesh is
// refined; a file that sets edge_strain only is scored on that, as before. Forces in contact that
// carry no strain at the instrument (a server older than schema 18) fail the criterion, naming why.
TEST(ExerciseScorer, TheStrainAtTheInstrumentIsScoredUnlessTheFileAsksForTheEdgeStrainOnly) {
  const std::string drill_body = R"("force_drill": {"force_n": 1.0, "tolerance_n": 0.1, "hold_s": 2}})";
  const std::string head = R"({"name": "drill", "kind": "force_drill", "scene": "liver", "time_limit_s": 60, )";
  const Exercise plain = parse_exercise(head + drill_body, "plain.json");
  const Exercise edge_only = parse_exercise(head + R"("limits": {"edge_strain": 0.5}, )" + drill_body, "edge.json");
  const Exercise both = parse_exercise(head + R"("limits": {"edge_strain": 0.5, "tip_strain": 0.2}, )" + drill_body, "both.json");
  const auto hold = [](double edge, double tip) {
    Session s("liver");
    s.tip_strain = tip;
    for (std::uint64_t k = 0; k <= 4000; ++k) s.step(100 + k, {0, 0, 0}, 1.0, edge);
    return s;
  };
  const auto has_criterion = [](const ScoreReport& r, const std::string& name) {
    return std::any_of(r.criteria.begin(), r.criteria.end(), [&](const Criterion& c) { return c.name == name; });
  };
  // A fine mesh's edge strain of 0.9 under a regional strain of 0.1: passes the plain file.
  const ScoreReport fine = hold(0.9, 0.1).score(plain);
  EXPECT_TRUE(fine.passed) << (fine.failures.empty() ? "" : fine.failures[0]);
  EXPECT_TRUE(has_criterion(fine, "strain at the instrument"));
  EXPECT_FALSE(has_criterion(fine, "largest edge strain"));
  EXPECT_DOUBLE_EQ(fine.max_tip_strain, 0.1);
  const ScoreReport strained = hold(0.2, 0.45).score(plain);
  EXPECT_TRUE(has_failure(strained, "strained too far at the instrument: 0.450 at the most (at most 0.400)")) << to_markdown(strained);
  const ScoreReport unmeasured = hold(0.2, 0.0).score(plain);
  EXPECT_TRUE(has_failure(unmeasured, "not measured")) << to_markdown(unmeasured);
  // The edge strain only: the strain at the instrument is neither scored nor missed.
  const ScoreReport edge = hold(0.9, 0.0).score(edge_only);
  EXPECT_FALSE(has_criterion(edge, "strain at the instrument"));
  EXPECT_TRUE(has_failure(edge, "largest edge strain 0.900")) << to_markdown(edge);
  EXPECT_TRUE(hold(0.3, 0.0).score(edge_only).passed);
  // Both: each against its own limit.
  EXPECT_TRUE(hold(0.3, 0.15).score(both).passed);
  EXPECT_TRUE(has_failure(hold(0.3, 0.21).score(both), "at the instrument"));
  EXPECT_TRUE(has_failure(hold(0.6, 0.15).score(both), "largest edge strain"));
}

// An incision along the line from (-25, 0) to (25, 0) mm off the top's centre, 10 mm deep: the
// scalpel comes down until it touches at z = 40 mm (its contact point), presses on with the button
// up until its tip is 10 mm below that, holds the cut button, draws 50 mm along x at y = 2 mm (the
// blade passing through: no contact force) and lets go. Length, deviation and depth are those of
// the path; 6 mm off the line, or 4 mm deep, fails naming why.
TEST(ExerciseScorer, IncisionLengthDepthAndLineAreThoseOfTheBladesPath) {
  const Exercise e = parse_exercise(R"({"name": "incision", "kind": "incision", "scene": "liver", "instrument": 4, "time_limit_s": 60,
    "incision": {"from_m": [-0.025, 0], "to_m": [0.025, 0], "depth_m": 0.01, "depth_tolerance_m": 0.003, "line_tolerance_m": 0.004,
                 "length_tolerance_m": 0.008}})",
                                    "incision.json");
  // `pressed_through`: the blade cuts with the button up, because the server says it pressed
  // through above the scene's cut force (Force.cutting), until it is lifted out.
  const auto perform = [&](double y, double depth, bool pressed_through = false, double cut_strain = 0.2) {
    Session s("liver");
    s.instrument = 4;
    std::uint64_t tick = 101;
    for (int k = 0; k <= 10; ++k, ++tick) s.step(tick, {-0.025, y, 0.05 - 0.0005 * k}, k == 10 ? 0.5 : 0.0);  // touches: its sphere at 40 mm
    const double z_cut = 0.04 - depth;  // pressed on, button up, to a tip `depth` below where it touched
    for (int k = 1; k <= 50; ++k, ++tick) s.step(tick, {-0.025, y, 0.045 - (0.045 - z_cut) * k / 50.0}, 0.5);
    for (int k = 0; k <= 1000; ++k, ++tick)
      s.step(tick, {-0.025 + 0.05 * k / 1000.0, y, z_cut}, 0.0, 0.1, pressed_through ? 0u : 1u, pressed_through, k == 500 ? cut_strain : 0.05);
    s.step(tick++, {0.025, y, z_cut}, 0.0, 0.1, 0u);
    return std::pair{s.score(e), tick - 1};
  };
  const auto [good, end_tick] = perform(0.002, 0.01);
  ASSERT_TRUE(good.incision_length_m);
  EXPECT_NEAR(*good.incision_length_m, 0.05, 1e-12);
  EXPECT_NEAR(good.incision_deviation_m, 0.002, 1e-12);
  EXPECT_NEAR(good.incision_mean_depth_m, 0.01, 1e-12);
  EXPECT_NEAR(good.incision_max_depth_m, 0.01, 1e-12);
  EXPECT_EQ(good.incision_cut_strain, 0.2);  // the largest the forces carried
  EXPECT_TRUE(good.passed) << to_markdown(good);
  EXPECT_TRUE(good.completed);
  EXPECT_EQ(good.ending, "incision made");
  EXPECT_NEAR(good.time_s, static_cast<double>(end_tick - 100) / 1000.0, 1e-12);
  const auto [off, t1] = perform(0.006, 0.01);
  EXPECT_FALSE(off.passed);
  EXPECT_TRUE(has_failure(off, "off the line: 6.0 mm")) << to_markdown(off);
  const auto [shallow, t2] = perform(0.0, 0.004);
  EXPECT_TRUE(has_failure(shallow, "deep on average")) << to_markdown(shallow);
  const auto [through, t3] = perform(0.002, 0.01, true);
  ASSERT_TRUE(through.incision_length_m);
  EXPECT_NEAR(*through.incision_length_m, 0.05, 1e-12);
  EXPECT_NEAR(through.incision_mean_depth_m, 0.01, 1e-12);
  EXPECT_TRUE(through.passed) << to_markdown(through);
  EXPECT_EQ(through.ending, "incision made");
  // Tissue pulled apart where the blade cut (strain 0.6 above the limit 0.5) fails, naming it,
  // while the organ's largest strain (0.1) stays within it.
  const auto [torn, t4] = perform(0.002, 0.01, false, 0.6);
  EXPECT_FALSE(torn.passed);
  EXPECT_TRUE(has_failure(torn, "torn where the blade cut: strain 0.600")) << to_markdown(torn);
  EXPECT_FALSE(has_failure(torn, "strained too far")) << to_markdown(torn);
  (void)t4;
  (void)t3;
  (void)t1;
  (void)t2;
}
