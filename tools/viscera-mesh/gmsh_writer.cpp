#include "gmsh_writer.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace viscera::meshing {

std::string gmsh_text(const LabelledMesh& mesh, const std::vector<PhysicalGroup>& groups, const std::vector<std::int32_t>& held,
                      const PhysicalGroup& held_group) {
  std::vector<char> is_held(mesh.tets.size(), 0);
  for (const std::int32_t e : held) is_held[static_cast<std::size_t>(e)] = 1;
  // One volume entity per (label, held): entity tags from 1 in the order of `groups`.
  std::map<std::pair<std::int32_t, bool>, int> entity;
  for (const PhysicalGroup& g : groups)
    for (const bool h : {false, true}) {
      if (h && held_group.tag == 0) continue;
      bool used = false;
      for (std::size_t e = 0; e < mesh.tets.size() && !used; ++e) used = mesh.label[e] == g.tag && bool(is_held[e]) == h;
      if (used) entity.emplace(std::make_pair(g.tag, h), static_cast<int>(entity.size()) + 1);
    }
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n";
  s += std::to_string(groups.size() + (held_group.tag ? 1 : 0)) + "\n";
  for (const PhysicalGroup& g : groups) s += "3 " + std::to_string(g.tag) + " \"" + g.name + "\"\n";
  if (held_group.tag) s += "3 " + std::to_string(held_group.tag) + " \"" + held_group.name + "\"\n";
  s += "$EndPhysicalNames\n$Entities\n0 0 0 " + std::to_string(entity.size()) + "\n";
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& p : mesh.nodes) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  char line[256];
  std::vector<std::pair<int, std::pair<std::int32_t, bool>>> ordered;
  ordered.reserve(entity.size());
  for (const auto& [key, tag] : entity) ordered.push_back({tag, key});
  std::sort(ordered.begin(), ordered.end());
  for (const auto& [tag, key] : ordered) {
    std::snprintf(line, sizeof line, "%d %.17g %.17g %.17g %.17g %.17g %.17g ", tag, lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
    s += line;
    s += key.second ? "2 " + std::to_string(key.first) + " " + std::to_string(held_group.tag) : "1 " + std::to_string(key.first);
    s += " 0\n";
  }
  s += "$EndEntities\n$Nodes\n";
  const std::size_t n = mesh.nodes.size();
  s += "1 " + std::to_string(n) + " 1 " + std::to_string(n) + "\n3 1 0 " + std::to_string(n) + "\n";
  for (std::size_t k = 1; k <= n; ++k) s += std::to_string(k) + "\n";
  for (const auto& p : mesh.nodes) {
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    s += line;
  }
  s += "$EndNodes\n$Elements\n";
  s += std::to_string(ordered.size()) + " " + std::to_string(mesh.tets.size()) + " 1 " + std::to_string(mesh.tets.size()) + "\n";
  std::size_t id = 0;
  for (const auto& [tag, key] : ordered) {
    std::string block;
    std::size_t count = 0;
    for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
      if (mesh.label[e] != key.first || bool(is_held[e]) != key.second) continue;
      ++count;
      const auto& t = mesh.tets[e];
      block += std::to_string(++id) + " " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + " " +
               std::to_string(t[3] + 1) + "\n";
    }
    s += "3 " + std::to_string(tag) + " 4 " + std::to_string(count) + "\n" + block;
  }
  if (id != mesh.tets.size()) throw std::logic_error("gmsh_text: a tetrahedron's label has no physical group");
  s += "$EndElements\n";
  return s;
}

}  // namespace viscera::meshing
