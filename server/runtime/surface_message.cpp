#include "viscera/runtime/surface_message.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <unordered_map>

namespace viscera::runtime {

namespace proto = viscera::protocol;

proto::SurfaceTopology whole_surface(std::uint32_t mesh_id, std::uint32_t topology_generation, const std::string& organ_name,
                                     const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary) {
  proto::SurfaceTopology t;
  t.mesh_id = mesh_id;
  t.topology_generation = topology_generation;
  t.organ_name = organ_name;
  t.vertex_count = static_cast<std::uint32_t>(boundary.nodes.size());
  std::vector<std::uint32_t> vertex_of(mesh.nodes.size(), 0);
  t.rest_positions.reserve(3 * boundary.nodes.size());
  for (std::size_t k = 0; k < boundary.nodes.size(); ++k) {
    vertex_of[static_cast<std::size_t>(boundary.nodes[k])] = static_cast<std::uint32_t>(k);
    for (int d = 0; d < 3; ++d) t.rest_positions.push_back(static_cast<float>(mesh.nodes[static_cast<std::size_t>(boundary.nodes[k])][d]));
  }
  t.triangles.reserve(3 * boundary.triangles.size());
  for (const auto& tri : boundary.triangles)
    for (const auto n : tri) t.triangles.push_back(vertex_of[static_cast<std::size_t>(n)]);
  return t;
}

std::size_t surface_array_bytes(const proto::SurfaceTopology& t) {
  return 4 * (t.triangles.size() + t.rest_positions.size() + t.removed_vertices.size() + t.inserted_vertices.size() + t.removed_triangles.size());
}

std::optional<proto::SurfaceTopology> surface_patch(const SentSurface& sent, const proto::SurfaceTopology& now,
                                                    std::span<const std::int32_t> now_nodes) {
  if (now.patch || sent.mesh_id != now.mesh_id || now.topology_generation <= sent.topology_generation || now_nodes.size() != now.vertex_count)
    return std::nullopt;
  proto::SurfaceTopology p;
  p.patch = true;
  p.mesh_id = now.mesh_id;
  p.organ_name = now.organ_name;
  p.topology_generation = now.topology_generation;
  p.base_generation = sent.topology_generation;
  p.vertex_count = now.vertex_count;
  // Vertices: the kept ones must keep their order (both lists follow the boundary's sorted nodes).
  std::unordered_map<std::int32_t, std::uint32_t> sent_vertex;
  sent_vertex.reserve(sent.nodes.size());
  for (std::size_t k = 0; k < sent.nodes.size(); ++k) sent_vertex.emplace(sent.nodes[k], static_cast<std::uint32_t>(k));
  std::vector<char> kept(sent.nodes.size(), 0);
  std::int64_t last_kept = -1;
  for (std::size_t k = 0; k < now_nodes.size(); ++k) {
    const auto it = sent_vertex.find(now_nodes[k]);
    if (it == sent_vertex.end()) {
      p.inserted_vertices.push_back(static_cast<std::uint32_t>(k));
      p.rest_positions.insert(p.rest_positions.end(), now.rest_positions.begin() + static_cast<std::ptrdiff_t>(3 * k),
                              now.rest_positions.begin() + static_cast<std::ptrdiff_t>(3 * k + 3));
      continue;
    }
    if (static_cast<std::int64_t>(it->second) <= last_kept) return std::nullopt;
    last_kept = it->second;
    kept[it->second] = 1;
  }
  for (std::size_t k = 0; k < kept.size(); ++k)
    if (!kept[k]) p.removed_vertices.push_back(static_cast<std::uint32_t>(k));
  // Triangles, by mesh node: the sent ones that stay come first in the new list, in their order.
  const std::size_t sent_count = sent.triangles.size() / 3, now_count = now.triangles.size() / 3;
  const auto same = [&](std::size_t s, std::size_t n) {
    for (std::size_t c = 0; c < 3; ++c)
      if (sent.nodes[sent.triangles[3 * s + c]] != now_nodes[now.triangles[3 * n + c]]) return false;
    return true;
  };
  std::size_t j = 0;
  for (std::size_t s = 0; s < sent_count; ++s) {
    if (j < now_count && same(s, j))
      ++j;
    else
      p.removed_triangles.push_back(static_cast<std::uint32_t>(s));
  }
  p.triangles.assign(now.triangles.begin() + static_cast<std::ptrdiff_t>(3 * j), now.triangles.end());
  if (2 * surface_array_bytes(p) >= surface_array_bytes(now)) return std::nullopt;
  return p;
}

}  // namespace viscera::runtime
