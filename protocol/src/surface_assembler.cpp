#include "viscera/protocol/surface_assembler.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <stdexcept>
#include <string>

namespace viscera::protocol {

SurfaceTopology apply_surface_patch(const SurfaceTopology& base, const SurfaceTopology& patch) {
  const auto refuse = [](const std::string& why) { throw std::invalid_argument("surface patch: " + why); };
  if (!patch.patch || base.patch) refuse("needs a whole surface and a patch");
  if (patch.mesh_id != base.mesh_id || patch.base_generation != base.topology_generation)
    refuse("of mesh " + std::to_string(patch.mesh_id) + " generation " + std::to_string(patch.base_generation) + ", not of mesh " +
           std::to_string(base.mesh_id) + " generation " + std::to_string(base.topology_generation));
  const std::size_t n0 = base.vertex_count, n1 = patch.vertex_count;
  const std::size_t removed = patch.removed_vertices.size(), inserted = patch.inserted_vertices.size();
  if (removed > n0 || n0 - removed + inserted != n1 || (removed > 0 && patch.removed_vertices.back() >= n0))
    refuse(std::to_string(n0) + " vertices less " + std::to_string(removed) + " plus " + std::to_string(inserted) + " are not " + std::to_string(n1));
  if (patch.rest_positions.size() != 3 * inserted)
    refuse("rest positions for " + std::to_string(patch.rest_positions.size() / 3) + " of " + std::to_string(inserted) + " inserted vertices");
  SurfaceTopology out;
  out.mesh_id = patch.mesh_id;
  out.organ_name = patch.organ_name;
  out.topology_generation = patch.topology_generation;
  out.vertex_count = patch.vertex_count;
  out.rest_positions.resize(3 * n1);
  // The new numbering: inserted vertices at their indices, the base's kept ones in order between.
  std::vector<std::int64_t> new_of_old(n0, -1);
  std::size_t old = 0, r = 0, i = 0;
  for (std::size_t k = 0; k < n1; ++k) {
    const float* from = nullptr;
    if (i < inserted && patch.inserted_vertices[i] == k) {
      from = &patch.rest_positions[3 * i++];
    } else {
      while (r < removed && patch.removed_vertices[r] == old) ++old, ++r;
      if (old >= n0) refuse("inserted or removed vertices that do not ascend");
      new_of_old[old] = static_cast<std::int64_t>(k);
      from = &base.rest_positions[3 * old++];
    }
    for (int d = 0; d < 3; ++d) out.rest_positions[3 * k + static_cast<std::size_t>(d)] = from[d];
  }
  while (r < removed && patch.removed_vertices[r] == old) ++old, ++r;
  if (old != n0 || r != removed || i != inserted) refuse("inserted or removed vertices that do not ascend");
  const std::size_t t0 = base.triangles.size() / 3;
  if (!patch.removed_triangles.empty() && patch.removed_triangles.back() >= t0)
    refuse("removes triangle " + std::to_string(patch.removed_triangles.back()) + " of " + std::to_string(t0));
  out.triangles.reserve(base.triangles.size() - 3 * patch.removed_triangles.size() + patch.triangles.size());
  std::size_t rt = 0;
  for (std::size_t t = 0; t < t0; ++t) {
    if (rt < patch.removed_triangles.size() && patch.removed_triangles[rt] == t) {
      ++rt;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const std::int64_t v = new_of_old[base.triangles[3 * t + static_cast<std::size_t>(c)]];
      if (v < 0) refuse("triangle " + std::to_string(t) + " is kept on a removed vertex");
      out.triangles.push_back(static_cast<std::uint32_t>(v));
    }
  }
  for (const std::uint32_t v : patch.triangles) {
    if (v >= n1) refuse("an added triangle's vertex " + std::to_string(v) + " beyond " + std::to_string(n1));
    out.triangles.push_back(v);
  }
  return out;
}

bool SurfaceAssembler::take(const SurfaceTopology& message) {
  if (!message.patch) {
    surface_ = message;
    return true;
  }
  if (!surface_ || surface_->mesh_id != message.mesh_id || surface_->topology_generation != message.base_generation) {
    ++skipped_;
    return false;
  }
  try {
    surface_ = apply_surface_patch(*surface_, message);
    return true;
  } catch (const std::invalid_argument&) {
    ++skipped_;
    return false;
  }
}

}  // namespace viscera::protocol
