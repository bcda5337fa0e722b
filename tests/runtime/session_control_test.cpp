// Session control without organs or DDS: builders that the test controls stand in for the organ's  // SPDX-License-Identifier: Apache-2.0
// (a promise each), so the outcomes, the one-at-a-time rule, failures and the never-waiting stop
// are checked directly.
#include "viscera/runtime/session_control.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/runtime/organ.hpp"

namespace viscera::runtime {
namespace {

/// A scene folder of the test's own (ctest runs the tests of this file in parallel processes).
std::string scene_folder() {
  std::string dir = std::string(VISCERA_TEST_TMP) + "/scenes-" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json", dir + "/liver.json");
  std::ofstream(dir + "/broken.json") << "{\"name\": 1e999}";
  return dir;
}

protocol::SessionRequest request(protocol::Action a, std::uint64_t seq, const std::string& scene = {}) {
  protocol::SessionRequest r;
  r.client_id = 900;
  r.action = a;
  r.request_seq = seq;
  r.scene_name = scene;
  r.material.youngs_modulus_pa = 8000;
  return r;
}

template <class F>
std::optional<Prepared> wait_ready(SessionControl& s, F&& release) {
  release();
  for (int k = 0; k < 500; ++k) {
    if (auto p = s.take_ready()) return p;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return std::nullopt;
}

TEST(SessionControl, OneBuildAtATimeEachWithItsOutcome) {
  std::promise<void> go;
  std::shared_future<void> gate = go.get_future().share();
  std::uint32_t built_on_domain = 99;
  SessionControl s(
      scene_folder(),
      [&](const SceneSpec& spec) {
        gate.wait();
        built_on_domain = spec.domain_id;
        return std::make_shared<Organ>();
      },
      [&](const std::shared_ptr<const Organ>&, const protocol::MaterialChange&, double) -> std::shared_ptr<Organ> {
        throw common::InputError("set_material", 0, "youngs_modulus_pa", "too stiff");
      });
  EXPECT_EQ(s.scenes().loadable, std::vector<std::string>{"liver"});
  ASSERT_EQ(s.scenes().unreadable.size(), 1u);
  EXPECT_EQ(s.scenes().unreadable[0].first, "broken");
  EXPECT_EQ(s.start_scene(request(protocol::Action::load_scene, 1, "liver"), 7), std::nullopt);
  EXPECT_EQ(s.preparing(), "scene liver");
  EXPECT_FALSE(s.take_ready());  // still building
  EXPECT_EQ(s.start_material(request(protocol::Action::set_material, 2), nullptr, 1000), "busy: still preparing scene liver");
  EXPECT_EQ(s.start_scene(request(protocol::Action::load_scene, 3, "liver"), 7), "busy: still preparing scene liver");
  const auto done = wait_ready(s, [&] { go.set_value(); });
  ASSERT_TRUE(done);
  EXPECT_TRUE(done->organ);
  EXPECT_EQ(done->request.request_seq, 1u);
  EXPECT_EQ(built_on_domain, 7u);  // the server's domain, not the scene file's
  EXPECT_EQ(s.preparing(), "");
  // A build that fails gives its error, and the next may start.
  EXPECT_EQ(s.start_material(request(protocol::Action::set_material, 4), nullptr, 1000), std::nullopt);
  EXPECT_EQ(s.preparing(), "material youngs_modulus_pa 8000");
  const auto failed = wait_ready(s, [] {});
  ASSERT_TRUE(failed);
  EXPECT_FALSE(failed->organ);
  EXPECT_EQ(failed->error, "set_material: youngs_modulus_pa: too stiff");
}

TEST(SessionControl, AMissingOrBrokenSceneIsRefusedWithWhatThereIs) {
  SessionControl s(
      scene_folder(), [](const SceneSpec&) { return std::make_shared<Organ>(); },
      [](const std::shared_ptr<const Organ>&, const protocol::MaterialChange&, double) { return std::make_shared<Organ>(); });
  const auto missing = s.start_scene(request(protocol::Action::load_scene, 1, "kidney"), 0);
  ASSERT_TRUE(missing);
  EXPECT_NE(missing->find("no scene 'kidney' in "), std::string::npos);
  EXPECT_NE(missing->find("(available: liver)"), std::string::npos);
  const auto broken = s.start_scene(request(protocol::Action::load_scene, 2, "broken"), 0);
  ASSERT_TRUE(broken);
  EXPECT_NE(broken->find("broken.json:1: JSON: number overflow parsing '1e999'"), std::string::npos) << *broken;
}

TEST(SessionControl, KeepsTheLastEightOutcomesOldestFirst) {
  SessionControl s(scene_folder(), nullptr, nullptr);
  for (std::uint64_t k = 1; k <= 11; ++k) s.record(request(protocol::Action::set_physics_rate, k), k % 2 == 0, "outcome " + std::to_string(k));
  ASSERT_EQ(s.outcomes().size(), SessionControl::kOutcomesKept);
  EXPECT_EQ(s.outcomes().front().request_seq, 4u);
  EXPECT_EQ(s.outcomes().back().request_seq, 11u);
  EXPECT_FALSE(s.outcomes().back().accepted);
  EXPECT_EQ(s.outcomes().back().message, "outcome 11");
}

TEST(SessionControl, StoppingNeverWaitsForABuild) {
  auto go = std::make_shared<std::promise<void>>();
  std::shared_future<void> gate = go->get_future().share();
  const int abandoned_before = SessionControl::abandoned();
  auto s = std::make_unique<SessionControl>(
      scene_folder(),
      [gate](const SceneSpec&) {
        gate.wait();
        return std::make_shared<Organ>();
      },
      nullptr);
  ASSERT_EQ(s->start_scene(request(protocol::Action::load_scene, 1, "liver"), 0), std::nullopt);
  const auto t0 = std::chrono::steady_clock::now();
  s.reset();  // the build is blocked on the gate
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.1);
  EXPECT_EQ(SessionControl::abandoned(), abandoned_before + 1);
  go->set_value();  // let the abandoned build finish before the test program ends
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

}  // namespace
}  // namespace viscera::runtime
