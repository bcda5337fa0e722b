#include "viscera/tissue/integrator/boundary_conditions.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <array>
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

void extend_constraints(BoundaryConditions& bc, std::span<const NewNodeEnds> new_nodes, std::size_t nodes_before) {
  const std::size_t nodes = nodes_before + new_nodes.size();
  // Which axes each node holds at rest, as a fixed node or by an axis of its own.
  std::vector<std::array<char, 3>> held(nodes, {0, 0, 0});
  for (const std::int32_t n : bc.fixed_nodes) held[static_cast<std::size_t>(n)] = {1, 1, 1};
  for (const AxisConstraint& c : bc.fixed_axes) held[static_cast<std::size_t>(c.node)][static_cast<std::size_t>(c.axis)] = 1;
  const auto both_in = [](std::vector<std::int32_t>& set, const NewNodeEnds& n, std::size_t i) {
    const bool a = std::find(set.begin(), set.end(), n.a) != set.end(), b = std::find(set.begin(), set.end(), n.b) != set.end();
    if (a && b) set.push_back(static_cast<std::int32_t>(i));
  };
  for (std::size_t k = 0; k < new_nodes.size(); ++k) {
    const NewNodeEnds& n = new_nodes[k];
    const std::size_t i = nodes_before + k;
    const auto &a = held[static_cast<std::size_t>(n.a)], &b = held[static_cast<std::size_t>(n.b)];
    for (std::size_t c = 0; c < 3; ++c) held[i][c] = static_cast<char>(a[c] && b[c]);
    if (held[i][0] && held[i][1] && held[i][2]) {
      bc.fixed_nodes.push_back(static_cast<std::int32_t>(i));
    } else {
      for (int c = 0; c < 3; ++c)
        if (held[i][static_cast<std::size_t>(c)]) bc.fixed_axes.push_back({static_cast<std::int32_t>(i), c});
    }
    for (PrescribedMotion& p : bc.prescribed) both_in(p.nodes, n, i);
    for (PrescribedAxisMotion& p : bc.prescribed_axes) both_in(p.nodes, n, i);
  }
  if (!bc.nodal_forces.empty()) bc.nodal_forces.resize(nodes, Vec3::Zero());
}

}  // namespace viscera::tissue
