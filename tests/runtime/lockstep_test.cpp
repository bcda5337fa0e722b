// Lockstep (SimulationServer::run_lockstep): the same steps give the same bits, run after run and  // SPDX-License-Identifier: Apache-2.0
// on one physics thread or two; a change of one command by a micrometre shows (the comparison can
// fail); and the steps do what they say: the claim, the press, the material change and the pause
// take effect at the ticks named, with the recording's clock. The whole server in one process,
// its endpoints in memory.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <thread>
#include <tuple>

#include <gtest/gtest.h>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/simulation_server.hpp"

#include "lockstep_run.hpp"

namespace viscera::runtime {
namespace {

namespace proto = viscera::protocol;
using namespace testing;

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
template <std::size_t N>
bool same_bits(const std::array<double, N>& a, const std::array<double, N>& b) {
  for (std::size_t i = 0; i < N; ++i)
    if (!same_bits(a[i], b[i])) return false;
  return true;
}

/// The first difference between two runs, "" if none: every force (all but the wall-clock
/// stamps), every event (all but its text and stamp), every frame (positions to the bit).
std::string first_difference(const LockstepRun& a, const LockstepRun& b) {
  if (a.results.size() != b.results.size()) return "result counts differ";
  std::string why;
  for (std::size_t i = 0; i < a.results.size(); ++i) {
    const auto& x = a.results[i];
    const auto& y = b.results[i];
    const std::string at = "tick " + std::to_string(x.tick) + ": ";
    if (x.tick != y.tick || !same_bits(x.sim_time_s, y.sim_time_s) || x.error != y.error) return at + "clock or error";
    if (x.forces.size() != y.forces.size()) return at + "force counts";
    for (std::size_t k = 0; k < x.forces.size(); ++k) {
      const auto f = proto::decode_force(x.forces[k], &why), g = proto::decode_force(y.forces[k], &why);
      if (!f || !g) return at + "undecodable force";
      if (f->instrument_id != g->instrument_id || f->command_seq != g->command_seq || f->tick != g->tick ||
          (f->step_time_ns > 0) != (g->step_time_ns > 0) || f->in_contact != g->in_contact || f->cutting != g->cutting ||
          !same_bits(f->force, g->force) || !same_bits(f->torque, g->torque) || !same_bits(f->contact_point, g->contact_point) ||
          !same_bits(f->contact_normal, g->contact_normal) || !same_bits(f->stiffness, g->stiffness) ||
          !same_bits(f->penetration_m, g->penetration_m) || !same_bits(f->cut_edge_strain, g->cut_edge_strain) ||
          !same_bits(f->tip_strain, g->tip_strain))
        return at + "force " + std::to_string(k);
    }
    if (x.events.size() != y.events.size()) return at + "event counts";
    for (std::size_t k = 0; k < x.events.size(); ++k) {
      const auto e = proto::decode_event(x.events[k], &why), h = proto::decode_event(y.events[k], &why);
      if (!e || !h || e->kind != h->kind || e->tick != h->tick || e->request_seq != h->request_seq || !same_bits(e->sim_time_s, h->sim_time_s))
        return at + "event " + std::to_string(k);
    }
    if (x.frame.empty() != y.frame.empty()) return at + "frame presence";
    if (!x.frame.empty()) {
      const auto m = proto::decode_mesh_frame(x.frame, &why), n = proto::decode_mesh_frame(y.frame, &why);
      if (!m || !n || m->tick != n->tick || !same_bits(m->sim_time_s, n->sim_time_s) || m->topology_generation != n->topology_generation ||
          m->positions.size() != n->positions.size() ||
          std::memcmp(m->positions.data(), n->positions.data(), m->positions.size() * sizeof(float)) != 0)
        return at + "frame";
    }
  }
  return "";
}

TEST(Lockstep, TheSameStepsGiveTheSameBitsOnOneThreadAndOnTwoAndANudgedCommandShows) {
  const LockstepRun a = run(1), again = run(1), two = run(2);
  ASSERT_EQ(a.results.size(), static_cast<std::size_t>(kTicks + 1));
  EXPECT_EQ(first_difference(a, again), "");
  EXPECT_EQ(first_difference(a, two), "");
  const LockstepRun nudged = run(1, kFirstTick + 200);
  const std::string d = first_difference(a, nudged);
  EXPECT_NE(d, "");
  // The nudged command is answered before tick +200 and stepped in it: the difference shows there.
  EXPECT_EQ(d.rfind("tick " + std::to_string(kFirstTick + 200) + ":", 0), 0u) << d;
}

// The contact proxy (organ.contact "proxy") keeps state across ticks (where it holds, whether it
// slides): the same steps still give the same bits, and its forces are not the penalty's.
TEST(Lockstep, TheContactProxyGivesTheSameBitsOnEveryRunAndOnTwoThreads) {
  const auto with_proxy = [](SceneSpec& s) { s.contact_proxy = true; };
  const LockstepRun a = run(1, 0, {}, with_proxy), again = run(1, 0, {}, with_proxy), two = run(2, 0, {}, with_proxy);
  ASSERT_EQ(a.results.size(), static_cast<std::size_t>(kTicks + 1));
  EXPECT_EQ(first_difference(a, again), "");
  EXPECT_EQ(first_difference(a, two), "");
  EXPECT_NE(first_difference(a, run(1)), "");
  std::string why;
  int touching = 0;
  for (const auto& r : a.results)
    for (const auto& p : r.forces)
      if (const auto f = proto::decode_force(p, &why); f && f->in_contact && std::abs(f->force[2]) > 0.01) ++touching;
  EXPECT_GT(touching, 0) << "the script's probe presses the organ";
}

TEST(Lockstep, StepsTakeEffectAtTheTicksTheyNameOnTheRecordingsClock) {
  const LockstepRun a = run(1);
  ASSERT_EQ(a.results.size(), static_cast<std::size_t>(kTicks + 1));
  std::string why;
  std::size_t in_contact = 0, answers = 0, stepped = 0;
  std::vector<proto::Event> events;
  for (const auto& r : a.results) {
    EXPECT_EQ(r.error, "") << r.tick;
    for (const auto& p : r.forces) {
      const auto f = proto::decode_force(p, &why);
      ASSERT_TRUE(f) << why;
      in_contact += f->in_contact;
      // A stepped force carries its own tick; an answer the tick whose state answered it (the one before).
      if (f->step_time_ns > 0) {
        ++stepped;
        EXPECT_EQ(f->tick, r.tick);
      } else {
        ++answers;
        EXPECT_EQ(f->tick, r.tick - 1);
      }
    }
    for (const auto& p : r.events) events.push_back(*proto::decode_event(p, &why));
  }
  EXPECT_EQ(stepped, static_cast<std::size_t>(kTicks));  // from the tick after the claim: one per tick
  EXPECT_EQ(answers, static_cast<std::size_t>(kTicks));
  EXPECT_GT(in_contact, 200u);
  const auto find = [&](proto::EventKind k) -> const proto::Event* {
    for (const auto& e : events)
      if (e.kind == k) return &e;
    return nullptr;
  };
  ASSERT_TRUE(find(proto::EventKind::instrument_claimed));
  EXPECT_EQ(find(proto::EventKind::instrument_claimed)->tick, kFirstTick);
  ASSERT_TRUE(find(proto::EventKind::material_changed));  // built before the tick went on
  EXPECT_EQ(find(proto::EventKind::material_changed)->tick, kFirstTick + 150);
  EXPECT_EQ(find(proto::EventKind::material_changed)->request_seq, 1u);
  ASSERT_TRUE(find(proto::EventKind::paused));
  EXPECT_EQ(find(proto::EventKind::paused)->tick, kFirstTick + 250);
  // Simulated time: 1 ms a tick from the recording's 1 s, none while paused (+250 .. +259).
  const double dt = 1.0 / a.scene.physics_rate_hz;
  EXPECT_NEAR(a.results.back().sim_time_s, kFirstSimTime + (kTicks + 1 - 10) * dt, 1e-9);
  // The organ deformed: the last frame is not the first.
  const proto::LockstepResult* first_frame = nullptr;
  for (const auto& r : a.results)
    if (!r.frame.empty() && !first_frame) first_frame = &r;
  ASSERT_TRUE(first_frame);
  const auto f0 = proto::decode_mesh_frame(first_frame->frame, &why), f1 = proto::decode_mesh_frame(a.results.back().frame, &why);
  ASSERT_TRUE(f0 && f1);
  EXPECT_EQ(f1->tick, kFirstTick + kTicks);
  double moved = 0;
  for (std::size_t i = 0; i < f0->positions.size(); ++i) moved = std::max(moved, static_cast<double>(std::abs(f1->positions[i] - f0->positions[i])));
  EXPECT_GT(moved, 1e-3);
}

TEST(Lockstep, AStepForAnotherTickIsRefusedWithItsReason) {
  SceneSpec spec = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  MemoryEndpoints endpoints;
  MemoryLockstepLink link;
  SimulationServer server(spec, endpoints, {}, TickBudget{1e9}, true);  // lockstep: no real time to keep, as viscera-server --lockstep
  std::atomic<bool> stop{false};
  std::thread t([&] { server.run_lockstep(stop, link, {}); });
  link.push_step({5, 0.0, {}, {}, {}, false});
  link.push_step({7, 0.0, {}, {}, {}, false});  // 6 expected
  link.push_step({6, 0.0, {}, {}, {}, false});
  const auto results = link.wait_results(3, std::chrono::seconds(60));
  stop = true;
  t.join();
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(results[0].error, "");
  EXPECT_NE(results[1].error.find("expected tick 6"), std::string::npos) << results[1].error;
  EXPECT_EQ(results[2].error, "");
}

/// The scalpel (instrument 4) claimed, lowered into the organ's top with its button held (or
/// not: `button`), drawn 6 cm along x, lifted out and the button let go; a frame every 10 ticks.
std::vector<proto::LockstepStep> incision(const proto::Scene& scene, bool button = true) {
  const double cx = 0.5 * (scene.bounds_min[0] + scene.bounds_max[0]), cy = 0.5 * (scene.bounds_min[1] + scene.bounds_max[1]);
  const double z0 = scene.bounds_max[2] + 0.002, depth = 0.02;  // the blade from 18 mm under the top to 2 mm over it
  std::vector<proto::LockstepStep> steps;
  proto::LockstepStep first;
  first.tick = kFirstTick;
  first.sim_time_s = kFirstSimTime;
  first.requests.push_back(proto::encode(proto::SessionRequest{7, proto::Action::claim_instrument, 4}));
  steps.push_back(first);
  const int down = 100, along = 300, up = 100, probe = 400;
  first.requests.push_back(proto::encode(proto::SessionRequest{8, proto::Action::claim_instrument, 1}));
  steps.back() = first;
  for (int k = 1; k <= down + along + up + probe; ++k) {
    proto::LockstepStep s;
    s.tick = kFirstTick + static_cast<std::uint64_t>(k);
    proto::Command c;
    c.instrument_id = 4;
    c.client_id = 7;
    c.seq = static_cast<std::uint64_t>(k);
    c.client_stamp_ns = 1000 * k;
    const double a = std::clamp(static_cast<double>(k - down) / along, 0.0, 1.0);
    const double z = k <= down           ? z0 - depth * k / down
                     : k <= down + along ? z0 - depth
                                         : z0 - depth * (1.0 - static_cast<double>(k - down - along) / up);
    c.tip_position = {cx - 0.03 + 0.06 * a, cy, z};
    c.buttons = button && k < down + along + up ? 1u : 0u;
    if (k <= down + along + up) {
      s.commands.push_back(proto::encode(c));
      s.answers.push_back(proto::encode(c));
    } else {  // then a probe presses 1 cm into the cut's line
      proto::Command p;
      p.instrument_id = 1;
      p.client_id = 8;
      p.seq = static_cast<std::uint64_t>(k);
      p.client_stamp_ns = 1000 * k;
      p.tip_position = {cx, cy, z0 + 0.004 - 0.014 * static_cast<double>(k - down - along - up) / probe};
      s.commands.push_back(proto::encode(p));
      s.answers.push_back(proto::encode(p));
    }
    s.want_frame = k % 10 == 0;
    steps.push_back(s);
  }
  return steps;
}

TEST(Lockstep, AnIncisionOpensTheSurfaceTheSameWayOnEveryRunAndOnTwoThreads) {
  const Script held = [](const proto::Scene& scene) { return incision(scene, true); };
  const LockstepRun a = run(1, 0, held), again = run(1, 0, held), two = run(2, 0, held);
  ASSERT_EQ(a.results.size(), 901u);
  EXPECT_EQ(first_difference(a, again), "");
  EXPECT_EQ(first_difference(a, two), "");
  std::string why;
  std::vector<proto::Event> events;
  std::vector<proto::MeshFrame> frames;
  for (const auto& r : a.results) {
    EXPECT_EQ(r.error, "") << r.tick;
    for (const auto& p : r.events) events.push_back(*proto::decode_event(p, &why));
    if (!r.frame.empty()) frames.push_back(*proto::decode_mesh_frame(r.frame, &why));
  }
  const auto count = [&](proto::EventKind k) {
    return std::count_if(events.begin(), events.end(), [&](const proto::Event& e) { return e.kind == k; });
  };
  EXPECT_EQ(count(proto::EventKind::physics_reset), 0);
  EXPECT_EQ(count(proto::EventKind::cut_started), 1);
  ASSERT_EQ(count(proto::EventKind::cut_ended), 1);
  const auto ended = std::find_if(events.begin(), events.end(), [](const proto::Event& e) { return e.kind == proto::EventKind::cut_ended; });
  EXPECT_EQ(ended->instrument_id, 4u);
  EXPECT_EQ(ended->tick, kFirstTick + 500);  // the button let go in the last step
  std::cout << "[ figure ] " << ended->text << "\n";
  // The surface changed many times, its generation only ever rising, and it gained vertices (the
  // cut's two faces).
  ASSERT_GE(frames.size(), 50u);
  EXPECT_EQ(frames.front().topology_generation, 0u);
  for (std::size_t k = 1; k < frames.size(); ++k) EXPECT_GE(frames[k].topology_generation, frames[k - 1].topology_generation);
  EXPECT_GT(frames.back().topology_generation, 10u);
  EXPECT_GT(frames.back().positions.size(), frames.front().positions.size());
  std::cout << "[ figure ] incision: surface generation " << frames.back().topology_generation << ", surface vertices "
            << frames.front().positions.size() / 3 << " -> " << frames.back().positions.size() / 3 << "\n";
  // The scalpel's forces carry the strain where it cut, in the ticks it cut something, and only
  // while it cuts.
  int strained = 0;
  double cut_strain = 0;
  for (const auto& r : a.results)
    for (const auto& p : r.forces) {
      const auto f = proto::decode_force(p, &why);
      if (!f || f->instrument_id != 4 || f->cut_edge_strain == 0) continue;
      EXPECT_TRUE(f->cutting) << "tick " << f->tick;
      ++strained;
      cut_strain = std::max(cut_strain, f->cut_edge_strain);
    }
  EXPECT_GT(strained, 10);
  EXPECT_LT(cut_strain, 0.5);
  std::cout << "[ figure ] incision: " << strained << " forces carry the strain where the blade cut, at most " << cut_strain << "\n";
  // The probe on the cut's line feels the cut organ: its local model's stiffness is the tissue's
  // in series with the contact penalty (1000 N/m), from the compliance rebuilt after the stroke,
  // never the penalty's bound that a node the uncut compliance does not know would give.
  int pressed = 0, softened = 0;
  double k_min = 1e300, k_max = 0;
  for (const auto& r : a.results)
    for (const auto& p : r.forces) {
      const auto f = proto::decode_force(p, &why);
      if (!f || f->instrument_id != 1 || !f->in_contact || f->tick <= ended->tick) continue;
      const double k = f->stiffness[0] + f->stiffness[4] + f->stiffness[8];  // k n n^T: its trace is k
      ++pressed;
      softened += k < 0.95 * 1000;
      k_min = std::min(k_min, k);
      k_max = std::max(k_max, k);
    }
  ASSERT_GT(pressed, 100);
  EXPECT_EQ(softened, pressed);
  std::cout << "[ figure ] the probe on the cut: " << pressed << " forces in contact, local stiffness " << k_min << " to " << k_max << " N/m\n";
}

/// Scalpel 4 of the bundled scene presses through at its cut force without its button: the
/// incision starts at the first tick whose force reached it, the blade then passes through (no
/// force, `cutting`), and the stroke ends when the tip is lifted out. With the cut force above what
/// the tissue gives, the same hand only presses.
TEST(Lockstep, AScalpelPressedAboveTheScenesCutForceCutsWithoutItsButton) {
  const SceneSpec bundled = read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/liver.json");
  const auto scalpel = std::find_if(bundled.instruments.begin(), bundled.instruments.end(), [](const InstrumentSpec& i) { return i.id == 4; });
  ASSERT_NE(scalpel, bundled.instruments.end());
  const double cut_force = scalpel->cut_force_n;
  ASSERT_GT(cut_force, 0.0);
  const auto pressed = [](const proto::Scene& scene) { return incision(scene, false); };
  const LockstepRun a = run(1, 0, pressed), again = run(1, 0, pressed);
  EXPECT_EQ(first_difference(a, again), "");
  std::string why;
  std::vector<proto::Event> events;
  std::vector<proto::Force> forces;
  for (const auto& r : a.results) {
    for (const auto& p : r.events) events.push_back(*proto::decode_event(p, &why));
    for (const auto& p : r.forces)
      if (const auto f = proto::decode_force(p, &why); f && f->instrument_id == 4 && f->step_time_ns > 0) forces.push_back(*f);
  }
  const auto first = [&](proto::EventKind k) {
    return std::find_if(events.begin(), events.end(), [&](const proto::Event& e) { return e.kind == k; });
  };
  const auto count = [&](proto::EventKind k) {
    return std::count_if(events.begin(), events.end(), [&](const proto::Event& e) { return e.kind == k; });
  };
  ASSERT_EQ(count(proto::EventKind::cut_started), 1);
  ASSERT_EQ(count(proto::EventKind::cut_ended), 1);
  EXPECT_EQ(count(proto::EventKind::physics_reset), 0);
  const std::uint64_t started = first(proto::EventKind::cut_started)->tick, ended = first(proto::EventKind::cut_ended)->tick;
  double peak_before = 0;
  int through = 0;
  for (const proto::Force& f : forces) {
    const double F = std::sqrt(f.force[0] * f.force[0] + f.force[1] * f.force[1] + f.force[2] * f.force[2]);
    if (f.tick < started) {
      EXPECT_LT(F, cut_force) << "tick " << f.tick;
      EXPECT_FALSE(f.cutting) << "tick " << f.tick;
      peak_before = std::max(peak_before, F);
    } else if (f.tick == started) {
      EXPECT_GE(F, cut_force);  // the force that pressed it through
    } else if (f.tick <= ended) {  // the tick that lifted it out still stepped with the blade through
      EXPECT_TRUE(f.cutting) << "tick " << f.tick;
      EXPECT_FALSE(f.in_contact) << "tick " << f.tick;
      EXPECT_EQ(F, 0.0) << "tick " << f.tick;
      ++through;
    } else {
      EXPECT_FALSE(f.cutting) << "tick " << f.tick;
    }
  }
  EXPECT_GT(through, 300);  // drawn along and lifted
  // Pressed in, the blade cut tissue its tip had strained: the strain where it cut shows it.
  double cut_strain = 0;
  for (const proto::Force& f : forces) cut_strain = std::max(cut_strain, f.cut_edge_strain);
  EXPECT_GT(cut_strain, 1e-3);
  EXPECT_LT(cut_strain, 0.5);
  EXPECT_GT(ended, kFirstTick + 400);  // lifted out on the way up (ticks 401-500), not before
  std::cout << "[ figure ] pressed through at tick +" << started - kFirstTick << " (force before it at most " << peak_before << " N, cut force "
            << cut_force << " N), strain where it cut up to " << cut_strain << "; " << first(proto::EventKind::cut_ended)->text << " (ended at +"
            << ended - kFirstTick << ")\n";

  // A cut force above what the tissue gives: the same hand presses and cuts nothing.
  const LockstepRun firm = run(1, 0, pressed, [](SceneSpec& s) {
    for (InstrumentSpec& i : s.instruments) i.cut_force_n = i.kind == InstrumentKind::scalpel ? 50.0 : 0.0;
  });
  std::size_t cuts = 0, contacts = 0;
  for (const auto& r : firm.results) {
    for (const auto& p : r.events) cuts += proto::decode_event(p, &why)->kind == proto::EventKind::cut_started;
    for (const auto& p : r.forces) contacts += proto::decode_force(p, &why)->in_contact;
  }
  EXPECT_EQ(cuts, 0u);
  EXPECT_GT(contacts, 300u);
}

}  // namespace
}  // namespace viscera::runtime
