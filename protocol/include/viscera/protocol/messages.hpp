#pragma once  // SPDX-License-Identifier: Apache-2.0
// Plain C++ views of the protocol's messages, and their encoding and verified decoding. Every
// received payload goes through decode_*: the FlatBuffers Verifier, then ranges and finiteness;
// a payload that fails returns nullopt and says why (the receiver counts and drops it).
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace viscera::protocol {

using Vector3 = std::array<double, 3>;

struct Command {
  std::uint32_t instrument_id = 0, client_id = 0;
  std::uint64_t seq = 0;
  std::int64_t client_stamp_ns = 0;
  Vector3 tip_position{};
  std::array<double, 4> orientation{1, 0, 0, 0};
  double jaw_opening = 0;
  std::uint32_t buttons = 0;
};

struct Force {
  std::uint32_t instrument_id = 0, client_id = 0;
  std::uint64_t command_seq = 0;
  std::int64_t command_client_stamp_ns = 0, server_stamp_ns = 0, step_time_ns = 0;
  Vector3 force{}, torque{};
  bool in_contact = false;
  Vector3 contact_point{}, contact_normal{};
  std::array<double, 9> stiffness{};  ///< row-major [N/m]
  double penetration_m = 0;  ///< [m] tip depth in the tissue (added in schema 2)
  /// schema 7: the tick that stepped with the command (step_time_ns > 0), or whose state answered
  /// it at once (step_time_ns 0); 0 from older servers
  std::uint64_t tick = 0;
  /// schema 8: the organ's largest edge strain |L - L0| / L0 over that tick's force evaluations
  /// (a tissue-damage proxy); 0 from older servers
  double max_edge_strain = 0;
  /// schema 17: a scalpel's blade cutting (cut button held, or pressed through above the scene's
  /// cut force): it passes through the tissue; false from older servers
  bool cutting = false;
  /// schema 17: for a cutting scalpel, the largest edge strain of the tetrahedra its blade cut in
  /// that tick, just after it cut them (0 when it cut none); 0 from older servers
  double cut_edge_strain = 0;
  /// schema 18: the tissue's strain at the instrument after that tick: the tetrahedra's largest
  /// principal stretch strain |lambda - 1| averaged within the scene's strain radius of where it
  /// touches (0 out of contact; 0 from older servers)
  double tip_strain = 0;
  /// schema 19: +1 at each reset, scene load, material change, pause and resume: the organ under
  /// the tool jumped without the tool moving (a client fades its force in again); 0 from older servers
  std::uint32_t organ_epoch = 0;
  /// schema 20: Coulomb friction at the contact (the contact proxy's): the rendered tangential
  /// force is at most this times the normal force; 0 without friction, and from older servers
  double friction_mu = 0;
};

enum class Action : std::int8_t {
  claim_instrument = 0,
  release_instrument = 1,
  pause = 2,
  resume = 3,
  reset = 4,
  load_scene = 5,
  set_material = 6,
  set_physics_rate = 7,  // schema 3
  seek = 8,  // schema 7: replayers only
  take_over = 9,  // schema 10: an instructor takes an instrument from its owner, no gap
  hand_back = 10  // schema 10: and gives it back
};
const char* action_name(Action a);

/// The longest material file a set_material request carries [bytes] (a material file is about 1 KiB).
inline constexpr std::size_t kMaxMaterialFileBytes = 64 * 1024;

/// Material parameters to change at run time (SI); empty ones keep their values. Schema 14: or a
/// whole material file (docs/MATERIAL.md) that replaces the organ's material, the parameters then
/// applied to it.
struct MaterialChange {
  std::optional<double> youngs_modulus_pa, poisson_ratio, density_kg_m3, shear_q, damping_per_s;
  std::optional<std::string> file_text;  ///< the file's JSON, at most kMaxMaterialFileBytes
  std::string file_name;  ///< with file_text: the file's name, for people ([A-Za-z0-9._-], 1-64)
  bool empty() const { return !youngs_modulus_pa && !poisson_ratio && !density_kg_m3 && !shear_q && !damping_per_s && !file_text; }
};

struct SessionRequest {
  std::uint32_t client_id = 0;
  Action action = Action::claim_instrument;
  std::uint32_t instrument_id = 0;
  // schema 3:
  std::uint64_t request_seq = 0;
  std::string scene_name;  ///< load_scene: [A-Za-z0-9._-], at most 64, not starting with '.'
  MaterialChange material;  ///< set_material: at least one parameter
  double physics_rate_hz = 0;  ///< set_physics_rate: [10, 10000]
  double seek_s = 0;  ///< seek (schema 7): [s] from the recording's start, >= 0
  std::optional<std::uint64_t> scene_seed;  ///< load_scene (schema 9): seed of the drawn regions; none: the scene file's
};

struct InstrumentInfo {
  std::uint32_t instrument_id = 0;
  bool grasper = false;
  double tip_radius_m = 0;
  std::uint32_t owner_client_id = 0;
  bool scalpel = false;  ///< schema 15
  double blade_length_m = 0;  ///< schema 15: a scalpel's blade [m]
};

struct MaterialInfo {
  std::string name;
  double youngs_modulus_pa = 0;  ///< 0: not isotropic
  double poisson_ratio = 0;
  double density_kg_m3 = 0;
  double shear_q = 0;  ///< 0: elastic
  double damping_per_s = 0;
  double added_mass_fraction = 0;  ///< mass scaling of the smallest elements / organ mass (schema 4)
};

/// What the server did with a load_scene, set_material or set_physics_rate request.
struct RequestOutcome {
  std::uint32_t client_id = 0;
  std::uint64_t request_seq = 0;
  Action action = Action::load_scene;
  bool accepted = false;
  std::string message;
};

/// A material region as laid out (schema 9); positions in the organ's frame [m].
/// elements (schema 11): a set of elements the mesh file tagged, described by their volume-weighted
/// centroid (center) and the bounding box of their nodes (box_min, box_max).
enum class RegionShape : std::uint8_t { sphere, box, elements };

struct RegionInfo {
  std::string name;
  RegionShape shape = RegionShape::sphere;
  Vector3 center{};
  double radius_m = 0;
  Vector3 box_min{}, box_max{};
  double depth_m = 0;  ///< sphere: its top's depth below the surface
  std::uint32_t elements = 0;
  double volume_m3 = 0;
  std::string material_name;
  double youngs_modulus_pa = 0;  ///< 0: not isotropic
};

struct Scene {
  std::string name;
  double physics_rate_hz = 0;
  bool paused = false;
  std::vector<InstrumentInfo> instruments;
  Vector3 bounds_min{}, bounds_max{};
  // schema 3:
  std::uint32_t generation = 0;  ///< +1 per scene loaded; SurfaceTopology.mesh_id
  MaterialInfo material;
  std::vector<std::string> available_scenes;
  std::string preparing;  ///< scene or material being built in the background
  std::vector<RequestOutcome> recent_requests;  ///< the last few, oldest first
  std::vector<std::string> unreadable_scenes;  ///< schema 6: "name: error" for scene files that do not read
  std::vector<RegionInfo> regions;  ///< schema 9: the organ's material regions
};

struct TelemetryReport {
  std::int64_t server_stamp_ns = 0;
  std::uint64_t steps = 0;
  std::uint64_t late_ticks = 0;  ///< ended after their slot (wire: `overruns`); the next tick starts at once
  std::uint64_t rejected_messages = 0;
  double physics_rate_hz = 0, step_p50_us = 0, step_p99_us = 0, step_max_us = 0, jitter_p99_us = 0;
  std::uint64_t missed_slots = 0;  ///< slots that passed with no tick (schema 5; 0 from older servers)
  /// rejected_messages by reason (schema 6; all 0 from older servers; the last, schema 13: under a
  /// client id another DDS participant holds)
  std::uint64_t rejected_malformed = 0, rejected_not_owner = 0, rejected_unknown_instrument = 0, rejected_other_participant = 0;
};

/// An organ's boundary surface, sent once per mesh_id; frames list positions in its vertex order.
struct SurfaceTopology {
  std::uint32_t mesh_id = 0;
  std::string organ_name;
  std::uint32_t vertex_count = 0;
  std::vector<std::uint32_t> triangles;  ///< 3 vertex indices per triangle
  std::vector<float> rest_positions;  ///< [m] 3 per vertex
  std::uint32_t topology_generation = 0;  ///< schema 15: 0 as loaded, +1 per change (cuts)
  /// Schema 16: a patch of the surface of base_generation (surface_mesh.fbs says how it applies;
  /// surface_assembler.hpp applies it). Then rest_positions are the inserted vertices' only, and
  /// triangles those added.
  bool patch = false;
  std::uint32_t base_generation = 0;
  std::vector<std::uint32_t> removed_vertices, inserted_vertices, removed_triangles;
};

/// The deformed surface at one instant.
struct MeshFrame {
  std::uint32_t mesh_id = 0;
  std::uint64_t frame = 0;
  double sim_time_s = 0;
  std::int64_t server_stamp_ns = 0;
  std::vector<float> positions;  ///< [m] 3 per vertex
  std::uint64_t tick = 0;  ///< schema 7: the tick after which it was taken
  std::uint32_t topology_generation = 0;  ///< schema 15: the SurfaceTopology these vertices are of
};

enum class EventKind : std::int8_t {
  annotation = 0,
  instrument_claimed,
  instrument_released,
  paused,
  resumed,
  organ_reset,
  physics_reset,
  contact_started,
  contact_ended,
  grasped,
  let_go,
  scene_loaded,
  material_changed,
  physics_rate_changed,
  request_refused,  // schema 3
  cut_started,  // schema 15
  cut_ended
};
/// The kind's name; "unknown" for kinds added by a newer server (decoders pass them through).
const char* event_name(EventKind k);
/// Why an instrument was released (schema 12); code acts on it, the text is for people.
enum class EventReason : std::int8_t { unspecified = 0, by_owner, owner_silent, scene_replaced, handed_back };
/// The reason's name; "unknown" for reasons added by a newer server.
const char* event_reason_name(EventReason r);

/// Something that happened in a session (server events) or a client's annotation.
struct Event {
  std::uint32_t source_client_id = 0;  ///< 0: the server
  EventKind kind = EventKind::annotation;
  std::uint32_t instrument_id = 0, client_id = 0;
  double sim_time_s = 0;
  std::int64_t stamp_ns = 0;
  std::string text;  ///< at most 1024 bytes
  std::uint64_t tick = 0;  ///< schema 7: the tick at whose start it took effect (server events)
  std::uint64_t request_seq = 0;  ///< schema 7: the session request it concludes (0: none)
  EventReason reason = EventReason::unspecified;  ///< schema 12
  std::string scene;  ///< schema 12, scene_loaded: the scene loaded (at most 64 bytes)
};

/// A file the server built its organ from (schema 7).
struct LoadedFile {
  std::string role;  ///< scene | mesh | material | region_material_role(k)
  std::string path, sha256;
  std::vector<std::uint8_t> content;
};

/// The role of the material file of the scene's k-th material region.
inline std::string region_material_role(std::size_t k) { return "region." + std::to_string(k) + ".material"; }

/// What it takes to run the current scene again (schema 7).
struct SceneFiles {
  std::uint32_t generation = 0;
  std::string server_version, settings_json;
  std::vector<LoadedFile> files;
  std::uint64_t first_tick = 0;  ///< the scene's first tick
  double sim_time_s = 0;  ///< [s] at the scene's first tick's start
};

/// One lockstep tick asked for (schema 7): session requests and commands as their payloads.
struct LockstepStep {
  std::uint64_t tick = 0;
  double sim_time_s = 0;  ///< the first step only: the simulated time at its start
  std::vector<std::vector<std::uint8_t>> requests, commands, answers;
  bool want_frame = false;
};

/// What a lockstep tick produced: payloads of forces and events, the frame if asked.
struct LockstepResult {
  std::uint64_t tick = 0;
  double sim_time_s = 0;
  std::vector<std::vector<std::uint8_t>> forces, events;
  std::vector<std::uint8_t> frame;  ///< empty: none
  std::string error;
};

/// The protocol's schema version: what this build writes and the newest it reads.
inline constexpr int kSchemaVersion = 20;

std::vector<std::uint8_t> encode(const Command& c);
std::vector<std::uint8_t> encode(const Force& f);
std::vector<std::uint8_t> encode(const SessionRequest& r);
std::vector<std::uint8_t> encode(const Scene& s);
std::vector<std::uint8_t> encode(const TelemetryReport& t);
std::vector<std::uint8_t> encode(const SurfaceTopology& t);
std::vector<std::uint8_t> encode(const MeshFrame& m);
std::vector<std::uint8_t> encode(const Event& e);
std::vector<std::uint8_t> encode(const SceneFiles& f);
std::vector<std::uint8_t> encode(const LockstepStep& s);
std::vector<std::uint8_t> encode(const LockstepResult& r);

std::optional<Command> decode_command(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<Force> decode_force(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<SessionRequest> decode_session_request(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<Scene> decode_scene(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<TelemetryReport> decode_telemetry(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<SurfaceTopology> decode_surface_topology(std::span<const std::uint8_t> bytes, std::string* why);
/// Checks the frame on its own (finite positions within 10 m, whole vertices); that its vertex
/// count matches the topology of its mesh_id is the receiver's check (it holds the topology).
std::optional<MeshFrame> decode_mesh_frame(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<Event> decode_event(std::span<const std::uint8_t> bytes, std::string* why);
/// Checks each file's digest against its content.
std::optional<SceneFiles> decode_scene_files(std::span<const std::uint8_t> bytes, std::string* why);
/// The payloads inside are not decoded here (each has its own decoder).
std::optional<LockstepStep> decode_lockstep_step(std::span<const std::uint8_t> bytes, std::string* why);
std::optional<LockstepResult> decode_lockstep_result(std::span<const std::uint8_t> bytes, std::string* why);

/// SHA-256 of bytes, as 64 lowercase hex digits (OpenSSL's libcrypto).
std::string sha256_hex(std::span<const std::uint8_t> bytes);

}  // namespace viscera::protocol
