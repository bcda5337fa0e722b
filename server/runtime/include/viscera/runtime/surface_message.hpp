#pragma once  // SPDX-License-Identifier: Apache-2.0
// The organ's boundary surface as the SurfaceTopology stream carries it: whole, or, after a cut,
// as a patch of the surface its readers hold (schema 16, protocol/surface_assembler.hpp), whose
// size is bounded by what changed, not by the organ.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::runtime {

/// The boundary surface whole, its vertices in the order of boundary.nodes.
protocol::SurfaceTopology whole_surface(std::uint32_t mesh_id, std::uint32_t topology_generation, const std::string& organ_name,
                                        const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary);

/// A surface as its readers hold it, by mesh node.
struct SentSurface {
  std::uint32_t mesh_id = 0, topology_generation = 0;
  std::vector<std::int32_t> nodes;  ///< the mesh node of each vertex
  std::vector<std::uint32_t> triangles;  ///< 3 vertex indices per triangle
};

/// The patch that turns `sent` into `now` (a whole surface of the same mesh, vertex k the mesh node
/// now_nodes[k]), or nothing when the change cannot be one (vertices kept in another order) or
/// would not be smaller than half the whole surface. Kept triangles are found in order: the
/// boundary's update keeps the triangles that stay in their order and appends the new ones.
std::optional<protocol::SurfaceTopology> surface_patch(const SentSurface& sent, const protocol::SurfaceTopology& now,
                                                       std::span<const std::int32_t> now_nodes);

/// Bytes of a SurfaceTopology's arrays (4 per index or coordinate), what the patch saves.
std::size_t surface_array_bytes(const protocol::SurfaceTopology& t);

}  // namespace viscera::runtime
