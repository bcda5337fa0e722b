#include "viscera/tissue/integrator/boundary_conditions.hpp"

#include <stdexcept>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::tissue {

std::vector<double> lumped_masses(const TetMesh& mesh, std::span<const double> density_kg_m3) {
  if (density_kg_m3.size() != mesh.tets.size()) throw std::invalid_argument("lumped_masses: one density per tetrahedron expected");
  std::vector<double> m(mesh.nodes.size(), 0.0);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Tet& t = mesh.tets[e];
    const double quarter = 0.25 * density_kg_m3[e] * signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    for (int k = 0; k < 4; ++k) m[t[k]] += quarter;
  }
  return m;
}

std::vector<double> lumped_masses(const TetMesh& mesh, double density_kg_m3) {
  return lumped_masses(mesh, std::vector<double>(mesh.tets.size(), density_kg_m3));
}

std::vector<char> BoundaryConditions::constrained_mask(std::size_t node_count) const {
  std::vector<char> mask(3 * node_count, 0);
  const auto node = [&](std::int32_t i) {
    if (i < 0 || static_cast<std::size_t>(i) >= node_count)
      throw std::invalid_argument("BoundaryConditions: node " + std::to_string(i) + " out of range");
    for (int k = 0; k < 3; ++k) mask[3 * static_cast<std::size_t>(i) + k] = 1;
  };
  for (auto i : fixed_nodes) node(i);
  for (const auto& p : prescribed)
    for (auto i : p.nodes) node(i);
  for (const auto& p : prescribed_axes)
    for (auto i : p.nodes) {
      if (i < 0 || static_cast<std::size_t>(i) >= node_count || p.axis < 0 || p.axis > 2)
        throw std::invalid_argument("BoundaryConditions: bad prescribed axis motion");
      mask[3 * static_cast<std::size_t>(i) + p.axis] = 1;
    }
  for (const auto& c : fixed_axes) {
    if (c.node < 0 || static_cast<std::size_t>(c.node) >= node_count || c.axis < 0 || c.axis > 2)
      throw std::invalid_argument("BoundaryConditions: bad axis constraint");
    mask[3 * static_cast<std::size_t>(c.node) + c.axis] = 1;
  }
  return mask;
}

std::vector<std::int32_t> nodes_in_box(const TetMesh& mesh, const Box& box) {
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    if (box.contains(mesh.nodes[i])) out.push_back(static_cast<std::int32_t>(i));
  return out;
}

std::vector<std::int32_t> surface_nodes_in_box(const TetMesh& mesh, const Box& box) {
  std::vector<std::int32_t> out;
  for (auto i : extract_boundary(mesh).nodes)
    if (box.contains(mesh.nodes[i])) out.push_back(i);
  return out;
}

}  // namespace viscera::tissue
