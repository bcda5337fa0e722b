// What a tick may cost, against the explicit step's closed form: the stable step of a linear  // SPDX-License-Identifier: Apache-2.0
// material scales as sqrt(density / E), a tick of 1/rate takes ceil(1 / (rate dt)) sub-steps, and a
// scene or material whose tick needs more than the budget allows is refused before it runs, with
// the step, the sub-steps and the limit in the message.
#include "viscera/runtime/tick_budget.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace viscera::runtime {
namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const common::InputError& e) {
    return e.what();
  }
  return "no error";
}

SceneSpec liver() {
  SceneSpec s = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  return s;
}

TEST(TickBudget, SubStepsPerTickAreTheCeilingOfTickOverStep) {
  EXPECT_EQ(substeps_per_tick(4e-4, 1000), 3);
  EXPECT_EQ(substeps_per_tick(5e-4, 1000), 2);  // exactly two: not three from rounding
  EXPECT_EQ(substeps_per_tick(1e-3, 1000), 1);
  EXPECT_EQ(substeps_per_tick(2.8e-12, 1000), 357142858);
}

TEST(TickBudget, AStepThatCannotRunOrNeedsTooManySubStepsIsRefused) {
  const TickBudget budget{1.0 / 30, 10000};
  EXPECT_EQ(error_of([&] { check_tick_budget(std::nan(""), 0, 1000, budget, "s.json", "organ.material"); }),
            "s.json: organ.material: gives an explicit step of nan s, which cannot be run (not a positive number)");
  EXPECT_NE(error_of([&] { check_tick_budget(0.0, 0, 1000, budget, "s", "f"); }).find("cannot be run"), std::string::npos);
  // 1e-3 / 1e-7 = 10,000 sub-steps: just allowed; one more is not.
  EXPECT_EQ(error_of([&] { check_tick_budget(1e-7, 0, 1000, budget, "s", "f"); }), "no error");
  EXPECT_EQ(error_of([&] { check_tick_budget(0.99e-7, 0, 1000, budget, "s", "f"); }),
            "s: f: the stable explicit step is 9.9e-08 s, so a 1 ms tick needs 10102 sub-steps, more than the 10000 any tick may take");
  // Timed: 100 us per sub-step, 33.3 ms per tick: 333 sub-steps fit, 334 do not.
  EXPECT_EQ(error_of([&] { check_tick_budget(1e-3 / 333, 1e-4, 1000, budget, "s", "f"); }), "no error");
  EXPECT_EQ(error_of([&] { check_tick_budget(1e-3 / 334, 1e-4, 1000, budget, "s", "f"); }),
            "s: f: the stable explicit step is 2.99401e-06 s, so a 1 ms tick needs 334 sub-steps of 100 us each (measured here) = 33.4 ms per tick; "
            "a tick may take at most 33.3333 ms, which is 333 sub-steps on this machine (viscera-server --max-tick-ms)");
}

TEST(TickBudget, ATickLongerThanItsSlotIsNamedSlowerThanRealTime) {
  EXPECT_EQ(tick_cost(4e-4, 1e-4, 1000), "3 sub-steps of 100 us = 0.3 ms per 1 ms tick");
  EXPECT_EQ(tick_cost(2.5e-4, 1e-2, 1000),
            "4 sub-steps of 10000 us = 40 ms per 1 ms tick, slower than real time: about 25 ticks/s (2.5% of real time)");
}

TEST(TickBudget, TheLiverStepScalesAsOneOverTheRootOfItsModulusAndAStiffLiverIsRefusedAtOnce) {
  SceneSpec spec = liver();
  const TickBudget generous{1e9, 1'000'000'000};
  const auto soft = build_organ(spec, generous);
  // The same material 100 times stiffer, through a material file (the way a user makes one).
  const std::string stiff = std::string(VISCERA_TEST_TMP) + "/stiff-liver.json";
  std::filesystem::create_directories(VISCERA_TEST_TMP);
  std::ofstream(stiff) << R"({"density_kg_m3": 1060, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 500000, "poisson_ratio": 0.45},
    "viscoelasticity": {"model": "constant_q", "shear_q": 4.8, "bulk_q": null, "band_hz": [0.01, 10], "mechanisms": 3, "reference_frequency_hz": 2}})";
  spec.material = stiff;
  const auto hard = build_organ(spec, generous);
  EXPECT_NEAR(soft->integrator->dt_s() / hard->integrator->dt_s(), 10.0, 1e-6);
  // Young's modulus 1e12 Pa (the material files' ceiling): refused before anything is timed, at once.
  std::ofstream(stiff) << R"({"density_kg_m3": 1060, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 1e12, "poisson_ratio": 0.45}})";
  const auto t0 = std::chrono::steady_clock::now();
  const std::string why = error_of([&] { build_organ(spec); });
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_NE(why.find("liver.json: organ.material: the stable explicit step is "), std::string::npos) << why;
  EXPECT_NE(why.find("more than the 10000 any tick may take"), std::string::npos) << why;
  // The budget's boundary, from the closed form: exactly the sub-steps the soft liver needs pass.
  const long needed = substeps_per_tick(soft->integrator->dt_s(), spec.physics_rate_hz);
  spec.material = liver().material;
  EXPECT_NO_THROW(build_organ(spec, {1e9, needed}));
  EXPECT_THROW(build_organ(spec, {1e9, needed - 1}), common::InputError);
  // A measured sub-step is a positive time of the order of a force evaluation.
  EXPECT_GT(soft->substep_cost_s, 0);
  EXPECT_LT(soft->substep_cost_s, 0.1);
}

TEST(SceneFile, BadNumbersAndBadSiblingsNeverEscapeAsLibraryErrors) {
  const std::string dir = std::string(VISCERA_TEST_TMP) + "/scenes";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ifstream good(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  std::string text((std::istreambuf_iterator<char>(good)), std::istreambuf_iterator<char>());
  std::ofstream(dir + "/liver.json") << text;
  std::string over = text;
  over.replace(over.find("\"physics_rate_hz\": 1000"), 23, "\"physics_rate_hz\": 1e999");
  std::ofstream(dir + "/overflow.json") << over;
  std::string fraction = text;
  fraction.replace(fraction.find("\"physics_rate_hz\": 1000"), 23, "\"physics_rate_hz\": 333.3");
  std::ofstream(dir + "/fraction.json") << fraction;
  std::ofstream(dir + "/binary.json") << std::string("\x89PNG\r\n\x1a\n\0\0", 10);
  std::filesystem::create_directories(dir + "/folder.json");
  EXPECT_EQ(error_of([&] { read_scene_file(dir + "/overflow.json"); }), dir + "/overflow.json:4: JSON: number overflow parsing '1e999'");
  EXPECT_EQ(error_of([&] { read_scene_file(dir + "/fraction.json"); }), dir + "/fraction.json: physics_rate_hz: 333.3 is not a whole number");
  const SceneListing listing = list_scenes(dir);
  EXPECT_EQ(listing.loadable, std::vector<std::string>{"liver"});
  ASSERT_EQ(listing.unreadable.size(), 4u);
  EXPECT_EQ(listing.unreadable[0].first, "binary");
  EXPECT_NE(listing.unreadable[0].second.find("binary.json:1: JSON: parse error"), std::string::npos) << listing.unreadable[0].second;
  EXPECT_EQ(listing.unreadable[0].second.find('\x89'), std::string::npos);  // no raw bytes
  EXPECT_EQ(listing.unreadable[1].first, "folder");
  EXPECT_EQ(listing.unreadable[2].first, "fraction");
  EXPECT_EQ(listing.unreadable[3].first, "overflow");
}

TEST(SceneFile, ACutForceBelongsToAScalpelAndIsAPositiveForce) {
  const std::string dir = std::string(VISCERA_TEST_TMP) + "/cut-force";
  std::filesystem::create_directories(dir);
  std::ifstream good(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  const std::string text((std::istreambuf_iterator<char>(good)), std::istreambuf_iterator<char>());
  EXPECT_EQ(read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json").instruments.back().cut_force_n, 1.5);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    std::ofstream(dir + "/s.json") << t;
    return error_of([&] { read_scene_file(dir + "/s.json"); });
  };
  EXPECT_EQ(with("\"cut_force_n\": 1.5", "\"cut_force_n\": 0"), dir + "/s.json: instruments[3].cut_force_n: 0 is outside [0.01, 50]");
  EXPECT_EQ(with("\"cut_force_n\": 1.5", "\"cut_force_n\": \"hard\""), dir + "/s.json: instruments[3].cut_force_n: \"hard\" is not a number");
  EXPECT_EQ(with("\"kind\": \"probe\", \"tip_radius_m\": 0.006", "\"kind\": \"probe\", \"cut_force_n\": 2, \"tip_radius_m\": 0.006"),
            dir + "/s.json: instruments[0].cut_force_n: is for a scalpel; this is a probe");
}

}  // namespace
}  // namespace viscera::runtime
