#pragma once  // SPDX-License-Identifier: Apache-2.0
// A picture of a meshed organ for its report: the outer surface seen from above and in front
// (painter's order, flat shading), each label in its colour, the held faces darker, with a scale bar.
#include <string>
#include <vector>

#include "label_mesher.hpp"

namespace viscera::meshing {

struct PictureLabel {
  std::int32_t label = 0;
  std::string name;
};

/// SVG text of the organ's outer surface (nodes in the scene's frame: z up). `held` flags the
/// tetrahedra whose outer faces are held.
std::string organ_picture_svg(const LabelledMesh& mesh, const std::vector<PictureLabel>& labels, const std::vector<char>& held,
                              const std::string& title);

}  // namespace viscera::meshing
