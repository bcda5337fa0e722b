#pragma once  // SPDX-License-Identifier: Apache-2.0
// Tetrahedra of the labels of a label map, by CGAL's Mesh_3 on the labelled image: one Delaunay
// refinement for every label at once, so the tetrahedra of neighbouring labels share their
// interface's nodes and faces (a conforming mesh), followed by CGAL's sliver perturbation and
// exudation. The program that links this file carries CGAL's GPL-3.0-or-later as a whole (NOTICE);
// the file itself is Apache-2.0, as all of viscera's code.
#include <array>
#include <cstdint>
#include <vector>

#include "label_map.hpp"

namespace viscera::meshing {

struct LabelMeshRequest {
  std::vector<std::int32_t> labels;  ///< the labels meshed; other voxels are outside
  double edge_m = 0.008;  ///< the tetrahedra's and the surface triangles' size bound [m]
  double facet_distance_m = 0.0015;  ///< how far a surface triangle may stray from the label boundary [m]
  double sliver_bound_deg = 12;  ///< the dihedral angle perturbation and exudation try to reach
  bool optimize = false;  ///< CGAL's ODT smoothing before the sliver removal
  unsigned seed = 1;  ///< CGAL's random choices: the same seed, the same mesh
};

struct LabelledMesh {
  std::vector<Eigen::Vector3d> nodes;  ///< in the patient's space [m]
  std::vector<std::array<std::int32_t, 4>> tets;  ///< positively oriented
  std::vector<std::int32_t> label;  ///< the label of each tetrahedron
};

/// Meshes `request.labels` of `map` (the labels must be present). Deterministic for the same inputs.
LabelledMesh mesh_labels(const LabelMap& map, const LabelMeshRequest& request);

}  // namespace viscera::meshing
