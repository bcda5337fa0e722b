#pragma once  // SPDX-License-Identifier: Apache-2.0
// viscera-mesh's work, stage by stage: read the label map, mesh the organ's labels to a size or a
// count, measure the mesh against the map, find where it is held, write the mesh, the scene, the
// picture and the report, and load the scene as the server does (calibration, explicit step).
#include <string>
#include <vector>

#include "held_faces.hpp"

namespace viscera::meshing {

struct RegionLabel {
  std::int32_t label = 0;
  std::string name, material;
};

struct OrganRequest {
  std::string label_map;
  std::vector<std::int32_t> organ_labels;
  std::string organ_name = "organ";
  std::string material;
  std::vector<RegionLabel> regions;
  double nodule_radius_m = 0;  ///< 0: none
  std::string nodule_material;
  std::size_t target_tets = 12000;  ///< used when edge_m is 0
  double edge_m = 0;
  double facet_distance_m = 0;  ///< 0: the smallest voxel edge
  double sliver_bound_deg = 20;
  bool optimize = false;
  HoldRequest hold;  ///< touch_distance_m 0: one voxel diagonal
  bool table_frame = true;
  std::string out_dir, name;
  unsigned seed = 1;
  bool replace = false, quiet = false;
};

/// Does it all; returns the exit status (0). Throws InputError naming the file and field.
int make_organ(const OrganRequest& request);

}  // namespace viscera::meshing
