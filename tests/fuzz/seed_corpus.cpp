// Writes one valid payload of every message (and of every session action) into a directory, the  // SPDX-License-Identifier: Apache-2.0
// fuzzer's seed corpus: mutating valid FlatBuffers reaches the range and finiteness checks behind
// the Verifier, which random bytes seldom pass. Each seed must decode as its own type, or this fails.
// Usage: seed_corpus DIR
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "viscera/protocol/messages.hpp"

using namespace viscera::protocol;

namespace {
int failures = 0;

template <class Message, class Decode>
void seed(const std::filesystem::path& dir, const std::string& name, const Message& m, Decode decode) {
  const std::vector<std::uint8_t> bytes = encode(m);
  std::string why;
  if (!decode(bytes, &why)) {
    std::fprintf(stderr, "seed_corpus: %s does not decode: %s\n", name.c_str(), why.c_str());
    ++failures;
  }
  std::ofstream(dir / ("seed-" + name), std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: seed_corpus DIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);

  Command c;
  c.instrument_id = 1;
  c.client_id = 7;
  c.seq = 42;
  c.client_stamp_ns = 1'000'000;
  c.tip_position = {0.01, -0.02, 0.03};
  c.jaw_opening = 0.5;
  c.buttons = 1;
  seed(dir, "command", c, decode_command);

  Force f;
  f.instrument_id = 1;
  f.client_id = 7;
  f.command_seq = 42;
  f.force = {0.1, 0.2, -1.5};
  f.in_contact = true;
  f.contact_point = {0.01, 0, 0.02};
  f.contact_normal = {0, 0, 1};
  f.stiffness = {0, 0, 0, 0, 0, 0, 0, 0, 1000};
  f.penetration_m = 0.002;
  seed(dir, "force", f, decode_force);

  for (int a = static_cast<int>(Action::claim_instrument); a <= static_cast<int>(Action::set_physics_rate); ++a) {
    SessionRequest r;
    r.client_id = 7;
    r.action = static_cast<Action>(a);
    r.instrument_id = 1;
    r.request_seq = 3;
    if (r.action == Action::load_scene) r.scene_name = "liver-12k";
    if (r.action == Action::set_material) {
      r.material.youngs_modulus_pa = 5000;
      r.material.poisson_ratio = 0.45;
      r.material.shear_q = 4.8;
    }
    if (r.action == Action::set_physics_rate) r.physics_rate_hz = 500;
    seed(dir, std::string("session-") + action_name(r.action), r, decode_session_request);
  }

  Scene s;
  s.name = "liver";
  s.physics_rate_hz = 1000;
  s.instruments = {{1, false, 0.006, 7}, {3, true, 0.004, 0}};
  s.bounds_min = {-0.1, -0.1, 0};
  s.bounds_max = {0.1, 0.1, 0.1};
  s.generation = 2;
  s.material = {"liver", 5000, 0.45, 1060, 4.8, 2, 0.05};
  s.available_scenes = {"liver", "liver-12k"};
  s.recent_requests = {{7, 3, Action::load_scene, true, "loaded"}};
  seed(dir, "scene", s, decode_scene);

  seed(dir, "telemetry", TelemetryReport{5, 1000, 3, 1, 998, 440, 900, 1200, 20}, decode_telemetry);

  SurfaceTopology t;
  t.mesh_id = 2;
  t.organ_name = "liver";
  t.vertex_count = 4;
  t.triangles = {0, 1, 2, 0, 2, 3};
  t.rest_positions = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 0, 0, 0.01f};
  seed(dir, "surface-topology", t, decode_surface_topology);
  SurfaceTopology patch = t;  // schema 16: a patch of it
  patch.patch = true;
  patch.topology_generation = 1;
  patch.removed_vertices = {3};
  patch.inserted_vertices = {1};
  patch.rest_positions = {0.005f, 0, 0};
  patch.removed_triangles = {1};
  patch.triangles = {0, 1, 3};
  seed(dir, "surface-patch", patch, decode_surface_topology);

  MeshFrame m;
  m.mesh_id = 2;
  m.frame = 9;
  m.sim_time_s = 0.5;
  m.positions = t.rest_positions;
  seed(dir, "mesh-frame", m, decode_mesh_frame);

  Event e;
  e.kind = EventKind::grasped;
  e.instrument_id = 3;
  e.client_id = 7;
  e.sim_time_s = 1.25;
  e.text = "grasped 12 nodes";
  seed(dir, "event", e, decode_event);

  return failures == 0 ? 0 : 1;
}
