// Encoding and verified decoding of the organ's surface on the wire: its topology, whole or as a  // SPDX-License-Identifier: Apache-2.0
// patch of the one before (schema 16), and its frames.
#include <cmath>

#include "viscera/protocol/messages.hpp"

#include "mesh_frame_generated.h"
#include "surface_mesh_generated.h"
#include "verified_root.hpp"

namespace viscera::protocol {

namespace fb = viscera::wire;  // the flatc-generated types
using detail::kMaxPositionM;
using detail::verified_root;

std::vector<std::uint8_t> encode(const SurfaceTopology& t) {
  flatbuffers::FlatBufferBuilder b(
      96 + 4 * (t.triangles.size() + t.rest_positions.size() + t.removed_vertices.size() + t.inserted_vertices.size() + t.removed_triangles.size()));
  const auto name = b.CreateString(t.organ_name);
  const auto tris = b.CreateVector(t.triangles);
  const auto rest = b.CreateVector(t.rest_positions);
  flatbuffers::Offset<flatbuffers::Vector<std::uint32_t>> removed_v, inserted_v, removed_t;
  if (t.patch) {
    removed_v = b.CreateVector(t.removed_vertices);
    inserted_v = b.CreateVector(t.inserted_vertices);
    removed_t = b.CreateVector(t.removed_triangles);
  }
  b.Finish(fb::CreateSurfaceTopology(b, t.mesh_id, name, t.vertex_count, tris, rest, t.topology_generation, t.patch, t.base_generation, removed_v,
                                     inserted_v, removed_t),
           fb::SurfaceTopologyIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

std::vector<std::uint8_t> encode(const MeshFrame& m) {
  flatbuffers::FlatBufferBuilder b(64 + 4 * m.positions.size());
  const auto positions = b.CreateVector(m.positions);
  b.Finish(fb::CreateMeshFrame(b, m.mesh_id, m.frame, m.sim_time_s, m.server_stamp_ns, positions, m.tick, m.topology_generation),
           fb::MeshFrameIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

namespace {
/// Positions: whole vertices, finite, within the scene's extent.
bool valid_positions(const flatbuffers::Vector<float>* p, std::string* why) {
  if (!p || p->size() % 3 != 0) {
    *why = "positions missing or not 3 per vertex";
    return false;
  }
  for (const float v : *p)
    if (!std::isfinite(v) || std::abs(v) > kMaxPositionM) {
      *why = "a position is not finite or beyond 10 m";
      return false;
    }
  return true;
}
}  // namespace

namespace {
/// Indices that ascend strictly and lie below `below` (`what`: the field, for `why`).
bool ascending_below(const flatbuffers::Vector<std::uint32_t>* v, std::uint64_t below, const char* what, std::string* why) {
  if (!v) return true;
  for (flatbuffers::uoffset_t k = 0; k < v->size(); ++k)
    if (v->Get(k) >= below || (k > 0 && v->Get(k) <= v->Get(k - 1))) {
      *why = std::string(what) + "[" + std::to_string(k) + "] = " + std::to_string(v->Get(k)) + ": not ascending below " + std::to_string(below);
      return false;
    }
  return true;
}
std::vector<std::uint32_t> copy_of(const flatbuffers::Vector<std::uint32_t>* v) {
  return v ? std::vector<std::uint32_t>(v->begin(), v->end()) : std::vector<std::uint32_t>{};
}
}  // namespace

std::optional<SurfaceTopology> decode_surface_topology(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::SurfaceTopology>(bytes, why, fb::SurfaceTopologyIdentifier());
  if (!m) return std::nullopt;
  if (!valid_positions(m->rest_positions(), why)) return std::nullopt;
  SurfaceTopology t;
  t.mesh_id = m->mesh_id();
  t.organ_name = m->organ_name() ? m->organ_name()->str() : "";
  t.vertex_count = m->vertex_count();
  t.patch = m->patch();
  // A whole surface lists every vertex; a patch only those it inserts.
  const std::uint64_t listed = t.patch ? (m->inserted_vertices() ? m->inserted_vertices()->size() : 0) : t.vertex_count;
  if (m->rest_positions()->size() != 3 * listed) {
    *why = "rest_positions hold " + std::to_string(m->rest_positions()->size()) + " numbers for " + std::to_string(listed) +
           (t.patch ? " inserted vertices" : " vertices");
    return std::nullopt;
  }
  if (!m->triangles() || m->triangles()->size() % 3 != 0) {
    *why = "triangles missing or not 3 indices each";
    return std::nullopt;
  }
  for (const auto i : *m->triangles())
    if (i >= t.vertex_count) {
      *why = "triangle vertex " + std::to_string(i) + " beyond vertex_count " + std::to_string(t.vertex_count);
      return std::nullopt;
    }
  if (t.patch) {
    // The base's sizes are the reader's to check (SurfaceAssembler); these need none.
    if (!ascending_below(m->inserted_vertices(), t.vertex_count, "inserted_vertices", why) ||
        !ascending_below(m->removed_vertices(), std::uint64_t{1} << 32, "removed_vertices", why) ||
        !ascending_below(m->removed_triangles(), std::uint64_t{1} << 32, "removed_triangles", why))
      return std::nullopt;
    if (m->base_generation() >= m->topology_generation()) {
      *why = "a patch of generation " + std::to_string(m->topology_generation()) + " on base generation " + std::to_string(m->base_generation());
      return std::nullopt;
    }
    t.base_generation = m->base_generation();
    t.removed_vertices = copy_of(m->removed_vertices());
    t.inserted_vertices = copy_of(m->inserted_vertices());
    t.removed_triangles = copy_of(m->removed_triangles());
  }
  t.triangles.assign(m->triangles()->begin(), m->triangles()->end());
  t.rest_positions.assign(m->rest_positions()->begin(), m->rest_positions()->end());
  t.topology_generation = m->topology_generation();
  return t;
}

std::optional<MeshFrame> decode_mesh_frame(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::MeshFrame>(bytes, why, fb::MeshFrameIdentifier());
  if (!m) return std::nullopt;
  if (!valid_positions(m->positions(), why)) return std::nullopt;
  if (!std::isfinite(m->sim_time_s()) || m->sim_time_s() < 0) {
    *why = "sim_time_s not finite or negative";
    return std::nullopt;
  }
  return MeshFrame{m->mesh_id(),
                   m->frame(),
                   m->sim_time_s(),
                   m->server_stamp_ns(),
                   {m->positions()->begin(), m->positions()->end()},
                   m->tick(),
                   m->topology_generation()};
}

}  // namespace viscera::protocol
