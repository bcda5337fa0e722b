// Every decoder against good, truncated, garbage, wrong-schema and out-of-range payloads.  // SPDX-License-Identifier: Apache-2.0
#include "viscera/protocol/messages.hpp"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "viscera/protocol/request_json.hpp"

using namespace viscera::protocol;

namespace {
Command good_command() {
  Command c;
  c.instrument_id = 1;
  c.client_id = 7;
  c.seq = 42;
  c.client_stamp_ns = 123456789;
  c.tip_position = {0.01, -0.02, 0.03};
  return c;
}
}  // namespace

TEST(Messages, RoundTripsEveryMessage) {
  std::string why;
  const auto c = decode_command(encode(good_command()), &why);
  ASSERT_TRUE(c) << why;
  EXPECT_EQ(c->seq, 42u);
  EXPECT_EQ(c->tip_position[1], -0.02);
  Force f;
  f.instrument_id = 1;
  f.client_id = 7;
  f.command_seq = 42;
  f.force = {0.1, 0.2, 3.0};
  f.in_contact = true;
  f.stiffness[4] = 200;
  f.max_edge_strain = 0.137;
  f.cutting = true;
  f.cut_edge_strain = 0.31;
  f.tip_strain = 0.12;
  f.friction_mu = 0.15;
  const auto fd = decode_force(encode(f), &why);
  ASSERT_TRUE(fd) << why;
  EXPECT_TRUE(fd->cutting);
  EXPECT_EQ(fd->cut_edge_strain, 0.31);
  EXPECT_EQ(fd->tip_strain, 0.12);
  EXPECT_EQ(fd->friction_mu, 0.15);
  EXPECT_EQ(fd->force[2], 3.0);
  EXPECT_TRUE(fd->in_contact);
  EXPECT_EQ(fd->stiffness[4], 200);
  EXPECT_EQ(fd->max_edge_strain, 0.137);
  // An edge strain that cannot be: negative, not a number, beyond any organ that still runs.
  for (const double bad : {-0.1, std::nan(""), 1e6}) {
    Force g = f;
    g.max_edge_strain = bad;
    EXPECT_FALSE(decode_force(encode(g), &why)) << bad;
    Force h = f;
    h.cut_edge_strain = bad;
    EXPECT_FALSE(decode_force(encode(h), &why)) << bad;
    Force t = f;
    t.tip_strain = bad;
    EXPECT_FALSE(decode_force(encode(t), &why)) << bad;
    Force u = f;
    u.friction_mu = bad;  // a friction coefficient below 0, not a number, or beyond the scenes' 2
    EXPECT_FALSE(decode_force(encode(u), &why)) << bad;
  }
  const auto s = decode_session_request(encode(SessionRequest{7, Action::release_instrument, 2}), &why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->action, Action::release_instrument);
  Scene sc;
  sc.name = "liver";
  sc.physics_rate_hz = 1000;
  sc.instruments.push_back({1, false, 0.006, 7});
  const auto sd = decode_scene(encode(sc), &why);
  ASSERT_TRUE(sd) << why;
  EXPECT_EQ(sd->instruments.at(0).owner_client_id, 7u);
  const auto t = decode_telemetry(encode(TelemetryReport{1, 2, 3, 4, 999.0, 1, 2, 3, 4, 5}), &why);
  ASSERT_TRUE(t) << why;
  EXPECT_EQ(t->late_ticks, 3u);
  EXPECT_EQ(t->missed_slots, 5u);
  EXPECT_EQ(t->physics_rate_hz, 999.0);
}

TEST(Messages, RejectsTruncatedGarbageWrongSchemaAndBadNumbers) {
  std::string why;
  auto bytes = encode(good_command());
  for (std::size_t n : {0ul, 4ul, bytes.size() / 2, bytes.size() - 4}) {
    const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(n));
    EXPECT_FALSE(decode_command(cut, &why)) << "truncated to " << n;
  }
  std::mt19937_64 rng(1);
  int accepted = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> g(8 + rng() % 200);
    for (auto& b : g) b = static_cast<std::uint8_t>(rng());
    accepted += decode_command(g, &why).has_value();
  }
  EXPECT_EQ(accepted, 0);
  Scene sc;
  sc.name = "a scene, not a command";
  EXPECT_FALSE(decode_command(encode(sc), &why));  // wrong schema
  Command c = good_command();
  c.tip_position[0] = std::nan("");
  EXPECT_FALSE(decode_command(encode(c), &why));
  EXPECT_NE(why.find("tip_position"), std::string::npos);
  c = good_command();
  c.tip_position[2] = 1e6;
  EXPECT_FALSE(decode_command(encode(c), &why));
  c = good_command();
  c.orientation = {2, 0, 0, 0};
  EXPECT_FALSE(decode_command(encode(c), &why));
  c = good_command();
  c.client_id = 0;
  EXPECT_FALSE(decode_command(encode(c), &why));
  Force f;
  f.force = {std::numeric_limits<double>::infinity(), 0, 0};
  EXPECT_FALSE(decode_force(encode(f), &why));
  TelemetryReport t{1, 2, 3, 4, 999.0, 1, 2, 3, 4, 5};
  t.step_p99_us = std::nan("");
  EXPECT_FALSE(decode_telemetry(encode(t), &why));
  EXPECT_NE(why.find("step_time_p99_us"), std::string::npos) << why;
  t.step_p99_us = 2;
  t.physics_rate_hz = -1000;
  EXPECT_FALSE(decode_telemetry(encode(t), &why));
  EXPECT_NE(why.find("physics_rate_hz"), std::string::npos) << why;
}

namespace {
SurfaceTopology good_topology() {
  SurfaceTopology t;
  t.mesh_id = 1;
  t.organ_name = "tet";
  t.vertex_count = 4;
  t.triangles = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  t.rest_positions = {0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0, 0, 0, 0.1f};
  return t;
}
}  // namespace

TEST(Messages, SurfaceTopologyAndFramesRoundTripAndBadOnesAreRejected) {
  std::string why;
  const auto t = decode_surface_topology(encode(good_topology()), &why);
  ASSERT_TRUE(t) << why;
  EXPECT_EQ(t->triangles, good_topology().triangles);
  EXPECT_EQ(t->rest_positions, good_topology().rest_positions);
  EXPECT_EQ(t->organ_name, "tet");
  MeshFrame m{1, 7, 0.25, 99, good_topology().rest_positions};
  const auto md = decode_mesh_frame(encode(m), &why);
  ASSERT_TRUE(md) << why;
  EXPECT_EQ(md->frame, 7u);
  EXPECT_EQ(md->positions, m.positions);

  auto bad = good_topology();
  bad.triangles[4] = 4;  // a vertex that does not exist
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  EXPECT_NE(why.find("beyond vertex_count"), std::string::npos) << why;
  bad = good_topology();
  bad.vertex_count = 5;  // positions for 4
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  bad = good_topology();
  bad.triangles.pop_back();
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  bad = good_topology();
  bad.rest_positions[5] = std::nanf("");
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  m.positions[2] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(decode_mesh_frame(encode(m), &why));
  m.positions = {0, 0};  // not whole vertices
  EXPECT_FALSE(decode_mesh_frame(encode(m), &why));
  m.positions = {0, 0, 0};
  m.sim_time_s = -1;
  EXPECT_FALSE(decode_mesh_frame(encode(m), &why));
  EXPECT_FALSE(decode_mesh_frame(encode(good_command()), &why));  // wrong schema
  const auto bytes = encode(good_topology());
  EXPECT_FALSE(decode_surface_topology(std::span(bytes).first(bytes.size() / 2), &why));  // truncated
}

TEST(Messages, ASurfacePatchRoundTripsAndOneThatCannotApplyAnywhereIsRejected) {
  SurfaceTopology p;
  p.patch = true;
  p.mesh_id = 1;
  p.topology_generation = 3;
  p.base_generation = 2;
  p.vertex_count = 5;
  p.removed_vertices = {0, 4};
  p.inserted_vertices = {1, 3};
  p.rest_positions = {0, 0, 0.2F, 0.1F, 0.1F, 0};
  p.removed_triangles = {2};
  p.triangles = {0, 1, 2};
  std::string why;
  const auto d = decode_surface_topology(encode(p), &why);
  ASSERT_TRUE(d) << why;
  EXPECT_TRUE(d->patch);
  EXPECT_EQ(d->base_generation, 2u);
  EXPECT_EQ(d->removed_vertices, p.removed_vertices);
  EXPECT_EQ(d->inserted_vertices, p.inserted_vertices);
  EXPECT_EQ(d->removed_triangles, p.removed_triangles);
  EXPECT_EQ(d->rest_positions, p.rest_positions);
  // A whole surface decodes without the patch's fields, as schema 15 wrote it.
  EXPECT_FALSE(decode_surface_topology(encode(good_topology()), &why)->patch);
  auto bad = p;
  bad.inserted_vertices = {3, 1};  // not ascending
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  EXPECT_NE(why.find("inserted_vertices"), std::string::npos) << why;
  bad = p;
  bad.inserted_vertices = {1, 5};  // beyond the new vertex count
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  bad = p;
  bad.removed_triangles = {2, 2};
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  bad = p;
  bad.rest_positions.resize(3);  // positions for one of two inserted vertices
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
  bad = p;
  bad.base_generation = 3;  // a patch of its own generation
  EXPECT_FALSE(decode_surface_topology(encode(bad), &why));
}

TEST(Messages, EventsRoundTripAndBadOnesAreRejected) {
  std::string why;
  Event e{0, EventKind::grasped, 3, 12, 1.25, 77, ""};
  const auto d = decode_event(encode(e), &why);
  ASSERT_TRUE(d) << why;
  EXPECT_EQ(d->kind, EventKind::grasped);
  EXPECT_EQ(d->client_id, 12u);
  EXPECT_EQ(d->sim_time_s, 1.25);
  EXPECT_STREQ(event_name(d->kind), "grasped");
  Event note{900, EventKind::annotation, 0, 900, 0, 5, "bleeding at segment IV"};
  EXPECT_EQ(decode_event(encode(note), &why)->text, "bleeding at segment IV");
  note.text.assign(1025, 'x');
  EXPECT_FALSE(decode_event(encode(note), &why));
  EXPECT_NE(why.find("1025 bytes"), std::string::npos) << why;
  e.sim_time_s = std::nan("");
  EXPECT_FALSE(decode_event(encode(e), &why));
  auto bytes = encode(Event{});
  EXPECT_FALSE(decode_event(std::span(bytes).first(bytes.size() - 6), &why));  // truncated
  EXPECT_FALSE(decode_event(encode(good_command()), &why));  // another schema
}

TEST(Messages, EventsCarryAReasonAndTheSceneForCodeToActOn) {
  std::string why;
  Event released{0, EventKind::instrument_released, 1, 31, 2.0, 9, "the scene was replaced by liver-12k"};
  released.reason = EventReason::scene_replaced;
  const auto r = decode_event(encode(released), &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->reason, EventReason::scene_replaced);
  EXPECT_STREQ(event_reason_name(r->reason), "scene_replaced");
  Event loaded{0, EventKind::scene_loaded, 0, 900, 3.0, 10, "loaded scene liver-12k (explicit step 0.0005 s)"};
  loaded.scene = "liver-12k";
  EXPECT_EQ(decode_event(encode(loaded), &why)->scene, "liver-12k");
  // An event without them (an older server) reads as unspecified, with no scene.
  const auto old = decode_event(encode(Event{0, EventKind::paused, 0, 900, 1.0, 3, ""}), &why);
  ASSERT_TRUE(old) << why;
  EXPECT_EQ(old->reason, EventReason::unspecified);
  EXPECT_TRUE(old->scene.empty());
  // A reason from a newer server passes through as unknown; a negative one is refused.
  released.reason = static_cast<EventReason>(42);
  const auto newer = decode_event(encode(released), &why);
  ASSERT_TRUE(newer) << why;
  EXPECT_STREQ(event_reason_name(newer->reason), "unknown");
  released.reason = static_cast<EventReason>(-3);
  EXPECT_FALSE(decode_event(encode(released), &why));
  EXPECT_NE(why.find("negative event reason"), std::string::npos) << why;
  loaded.scene.assign(65, 'a');
  EXPECT_FALSE(decode_event(encode(loaded), &why));
}

TEST(Messages, RunTimeControlRequestsRoundTripAndBadOnesAreRejected) {
  std::string why;
  SessionRequest load;
  load.client_id = 900;
  load.action = Action::load_scene;
  load.request_seq = 1'000'000'000'001;
  load.scene_name = "liver-12k";
  const auto l = decode_session_request(encode(load), &why);
  ASSERT_TRUE(l) << why;
  EXPECT_EQ(l->scene_name, "liver-12k");
  EXPECT_EQ(l->request_seq, 1'000'000'000'001u);
  EXPECT_FALSE(l->scene_seed);  // absent: the scene file's seed (schema 9)
  load.scene_seed = 0;  // a seed of 0 is a seed, not "absent"
  ASSERT_TRUE(decode_session_request(encode(load), &why));
  EXPECT_EQ(decode_session_request(encode(load), &why)->scene_seed, std::optional<std::uint64_t>(0));
  load.scene_seed = 18'446'744'073'709'551'615u;
  EXPECT_EQ(decode_session_request(encode(load), &why)->scene_seed, load.scene_seed);
  // A scene name is a name in the server's scene directory, never a path.
  for (const std::string& bad : std::vector<std::string>{"", "../etc/passwd", "/etc/passwd", ".hidden", "a b", std::string(65, 'a')}) {
    load.scene_name = bad;
    EXPECT_FALSE(decode_session_request(encode(load), &why)) << "scene_name '" << bad << "'";
  }
  SessionRequest mat;
  mat.client_id = 900;
  mat.action = Action::set_material;
  mat.material.youngs_modulus_pa = 8000;
  mat.material.shear_q = 3;
  const auto m = decode_session_request(encode(mat), &why);
  ASSERT_TRUE(m) << why;
  EXPECT_EQ(m->material.youngs_modulus_pa, 8000);
  EXPECT_EQ(m->material.shear_q, 3);
  EXPECT_FALSE(m->material.poisson_ratio);  // absent stays absent (FlatBuffers optional scalar)
  EXPECT_FALSE(m->material.density_kg_m3);
  const auto rejects = [&](const MaterialChange& c, const std::string& field) {
    SessionRequest r = mat;
    r.material = c;
    EXPECT_FALSE(decode_session_request(encode(r), &why)) << field;
    EXPECT_NE(why.find(field), std::string::npos) << why;
  };
  rejects({std::nan(""), {}, {}, {}, {}}, "youngs_modulus_pa");
  rejects({-5.0, {}, {}, {}, {}}, "youngs_modulus_pa");
  rejects({{}, 0.5, {}, {}, {}}, "poisson_ratio");
  rejects({{}, {}, 0.0, {}, {}}, "density_kg_m3");
  rejects({{}, {}, {}, std::numeric_limits<double>::infinity(), {}}, "shear_q");
  rejects({{}, {}, {}, {}, -1.0}, "damping_per_s");
  rejects({}, "material");  // nothing to change
  // Schema 14: a whole material file travels as text under a plain name, up to 64 KiB; the
  // recorded form (request_json) keeps it, so a re-simulation sends the same bytes.
  MaterialChange file;
  file.file_name = "material.json";
  file.file_text = R"({"name": "fitted", "density_kg_m3": 1060})";
  file.youngs_modulus_pa = 9000;
  SessionRequest with_file = mat;
  with_file.material = file;
  const auto f = decode_session_request(encode(with_file), &why);
  ASSERT_TRUE(f) << why;
  EXPECT_EQ(f->material.file_name, "material.json");
  EXPECT_EQ(f->material.file_text, file.file_text);
  EXPECT_EQ(f->material.youngs_modulus_pa, 9000);
  const auto again = session_request_from_json(to_json(*f), &why);
  ASSERT_TRUE(again) << why;
  EXPECT_EQ(again->material.file_text, file.file_text);
  EXPECT_EQ(again->material.file_name, "material.json");
  file.youngs_modulus_pa.reset();
  file.file_text = std::string(kMaxMaterialFileBytes, ' ');
  with_file.material = file;
  EXPECT_TRUE(decode_session_request(encode(with_file), &why)) << why;  // the limit itself passes
  file.file_text->push_back(' ');
  rejects(file, "file_text");
  file.file_text = "{}";
  for (const std::string& bad : std::vector<std::string>{"", "../material.json", "/etc/passwd", ".hidden", "a b.json", std::string(65, 'a')}) {
    file.file_name = bad;
    rejects(file, "file_name");
  }
  SessionRequest rate;
  rate.client_id = 900;
  rate.action = Action::set_physics_rate;
  rate.physics_rate_hz = 500;
  ASSERT_TRUE(decode_session_request(encode(rate), &why)) << why;
  for (double bad : {5.0, 20000.0, std::nan("")}) {
    rate.physics_rate_hz = bad;
    EXPECT_FALSE(decode_session_request(encode(rate), &why)) << bad;
  }
}

TEST(Messages, SceneStateCarriesMaterialScenesAndOutcomes) {
  Scene sc;
  sc.name = "liver";
  sc.physics_rate_hz = 500;
  sc.generation = 3;
  sc.material = {"liver", 5000, 0.45, 1060, 4.8, 2, 0.05};
  sc.available_scenes = {"liver", "liver-12k"};
  sc.preparing = "scene liver-12k";
  sc.recent_requests.push_back({900, 17, Action::load_scene, false, "no scene 'x'"});
  sc.recent_requests.push_back({901, 18, Action::set_physics_rate, true, "physics rate 500 Hz"});
  std::string why;
  const auto d = decode_scene(encode(sc), &why);
  ASSERT_TRUE(d) << why;
  EXPECT_EQ(d->generation, 3u);
  EXPECT_EQ(d->material.poisson_ratio, 0.45);
  EXPECT_EQ(d->material.shear_q, 4.8);
  EXPECT_EQ(d->material.added_mass_fraction, 0.05);  // schema 4
  EXPECT_EQ(d->available_scenes, sc.available_scenes);
  EXPECT_EQ(d->preparing, "scene liver-12k");
  ASSERT_EQ(d->recent_requests.size(), 2u);
  EXPECT_EQ(d->recent_requests[0].request_seq, 17u);
  EXPECT_FALSE(d->recent_requests[0].accepted);
  EXPECT_EQ(d->recent_requests[1].action, Action::set_physics_rate);
  EXPECT_EQ(d->recent_requests[1].message, "physics rate 500 Hz");
  // Material regions (schema 9).
  RegionInfo nodule;
  nodule.name = "nodule";
  nodule.center = {0.01, -0.02, 0.03};
  nodule.radius_m = 0.012;
  nodule.depth_m = 0.005;
  nodule.elements = 9;
  nodule.volume_m3 = 1e-5;
  nodule.material_name = "nodule";
  nodule.youngs_modulus_pa = 20000;
  RegionInfo lobe;
  lobe.name = "lobe";
  lobe.shape = RegionShape::box;
  lobe.box_min = {-1, -2, -3};
  lobe.box_max = {1, 2, 3};
  RegionInfo tumour;
  tumour.name = "tumour";
  tumour.shape = RegionShape::elements;
  tumour.center = {0.1, 0.2, 0.3};
  sc.regions = {nodule, lobe, tumour};
  const auto r = decode_scene(encode(sc), &why);
  ASSERT_TRUE(r) << why;
  ASSERT_EQ(r->regions.size(), 3u);
  EXPECT_EQ(r->regions[2].shape, RegionShape::elements);
  EXPECT_EQ(r->regions[2].center[2], 0.3);
  EXPECT_EQ(r->regions[0].name, "nodule");
  EXPECT_EQ(r->regions[0].shape, RegionShape::sphere);
  EXPECT_EQ(r->regions[0].center[1], -0.02);
  EXPECT_EQ(r->regions[0].radius_m, 0.012);
  EXPECT_EQ(r->regions[0].elements, 9u);
  EXPECT_EQ(r->regions[0].youngs_modulus_pa, 20000);
  EXPECT_EQ(r->regions[1].shape, RegionShape::box);
  EXPECT_EQ(r->regions[1].box_max[2], 3);
  sc.regions[0].center[0] = std::nan("");
  EXPECT_FALSE(decode_scene(encode(sc), &why));
  sc.regions.clear();
  sc.material.added_mass_fraction = INFINITY;
  EXPECT_FALSE(decode_scene(encode(sc), &why));
  sc.material.added_mass_fraction = 0;
  sc.material.youngs_modulus_pa = std::nan("");
  EXPECT_FALSE(decode_scene(encode(sc), &why));
}

TEST(Messages, EventKindsOfANewerServerPassThroughAsUnknown) {
  std::string why;
  Event e{0, static_cast<EventKind>(100), 0, 0, 1.0, 5, "from the future"};
  const auto d = decode_event(encode(e), &why);
  ASSERT_TRUE(d) << why;
  EXPECT_STREQ(event_name(d->kind), "unknown");
  EXPECT_EQ(d->text, "from the future");
  EXPECT_STREQ(event_name(EventKind::request_refused), "request_refused");
  e.kind = static_cast<EventKind>(-3);
  EXPECT_FALSE(decode_event(encode(e), &why));
}
