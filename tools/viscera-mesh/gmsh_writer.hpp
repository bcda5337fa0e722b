#pragma once  // SPDX-License-Identifier: Apache-2.0
// A labelled tetrahedral mesh as a Gmsh 4.1 ASCII file: a physical volume group per label (named),
// and one more for the held tetrahedra, which also belong to their label's group (Gmsh keeps
// several physical groups on one volume entity). Gmsh, viscera's reader and ParaView open it.
#include <string>
#include <vector>

#include "label_mesher.hpp"

namespace viscera::meshing {

struct PhysicalGroup {
  std::int32_t tag = 0;
  std::string name;
};

/// The file's text. `groups[k]` names label `groups[k].tag`; every tetrahedron's label must be one
/// of them. `held` (ascending tetrahedron indices) form the group `held_group`, if it has a tag.
std::string gmsh_text(const LabelledMesh& mesh, const std::vector<PhysicalGroup>& groups, const std::vector<std::int32_t>& held,
                      const PhysicalGroup& held_group);

}  // namespace viscera::meshing
