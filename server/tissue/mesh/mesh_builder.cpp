#include "viscera/tissue/mesh/mesh_builder.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/mesh/mesh_validation.hpp"

namespace viscera::tissue {

using common::InputError;

void MeshBuilder::add_node(long long id, const Vec3& p, long line) {
  if (!p.allFinite()) throw InputError(source_, line, "node " + std::to_string(id), "coordinates are not finite");
  const auto [it, inserted] = index_of_.emplace(id, static_cast<std::int32_t>(nodes_.size()));
  if (!inserted) throw InputError(source_, line, "node " + std::to_string(id), "duplicate node id");
  nodes_.push_back(p);
  node_ids_.push_back(id);
  node_lines_.push_back(line);
}

void MeshBuilder::add_tet(const std::array<long long, 4>& ids, long long element, long line, std::span<const int> groups) {
  tets_.push_back({ids, element, line, groups_.size(), groups.size()});
  groups_.insert(groups_.end(), groups.begin(), groups.end());
}

TetMesh MeshBuilder::build() {
  TetMesh mesh;
  mesh.source = source_;
  mesh.nodes = std::move(nodes_);
  mesh.tets.reserve(tets_.size());
  std::map<int, std::vector<std::int32_t>> sets;  // by tag
  MeshOrigin origin;
  origin.node_ids = std::move(node_ids_);
  origin.node_lines = std::move(node_lines_);
  for (const PendingTet& p : tets_) {
    origin.element_ids.push_back(p.element);
    origin.element_lines.push_back(p.line);
    Tet t;
    for (int k = 0; k < 4; ++k) {
      const auto it = index_of_.find(p.ids[k]);
      if (it == index_of_.end())
        throw InputError(source_, p.line, "element " + std::to_string(p.element),
                         "references node " + std::to_string(p.ids[k]) + ", which does not exist");
      t[k] = it->second;
    }
    for (std::size_t g = p.first_group; g < p.first_group + p.group_count; ++g)
      sets[groups_[g]].push_back(static_cast<std::int32_t>(mesh.tets.size()));
    mesh.tets.push_back(t);
  }
  for (auto& [tag, tets] : sets) {
    tets.erase(std::unique(tets.begin(), tets.end()), tets.end());  // a group listed twice for one element
    const auto name = group_names_.find(tag);
    mesh.element_sets.push_back({tag, name == group_names_.end() ? std::string() : name->second, std::move(tets)});
  }
  if (mesh.tets.empty()) throw InputError(source_, 0, "", "contains no tetrahedra");
  validate_mesh(mesh, &origin);
  return mesh;
}

}  // namespace viscera::tissue
