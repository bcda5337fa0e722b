#pragma once  // SPDX-License-Identifier: Apache-2.0
// Material regions laid out on an organ's mesh (docs/SCENE.md, "Material regions"): each element
// whose centroid lies inside a region's sphere or box, or that the mesh file tagged into the
// region's element set, takes the region's material (a later region over an earlier one). A sphere whose centre is drawn from a seed lands where it
// lies wholly inside the organ, its top between the stated depths below the surface (a surface facing the stated way, if one is stated), and clear of
// the fixed slab; the draw is a fixed function of the seed, the mesh and the scene (the same on any machine).
#include <cstdint>
#include <string>
#include <vector>

#include "viscera/runtime/scene_file.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::runtime {

struct PlacedRegion {
  std::string name;
  RegionSpec::Shape shape = RegionSpec::Shape::sphere;
  tissue::Vec3 center_m = tissue::Vec3::Zero();  ///< sphere; element set: its elements' volume-weighted centroid
  double radius_m = 0;
  tissue::Box box{tissue::Vec3::Zero(), tissue::Vec3::Zero()};  ///< box; element set: its nodes' bounding box
  double depth_m = 0;  ///< sphere: its top's depth below the organ's surface (distance to the surface minus radius)
  std::size_t elements = 0;
  double volume_m3 = 0;  ///< of its elements
};

struct RegionLayout {
  std::vector<PlacedRegion> regions;
  /// Per element: 0 for the organ's material, k for regions[k - 1]'s; empty when there is no region.
  std::vector<std::uint16_t> material_of_tet;
};

/// Lays `specs` out on `mesh`. `keep_out`: the fixed slab, which a drawn sphere must not touch.
/// Throws InputError naming `source` and the region's field when a region holds no element or no
/// place satisfies a drawn sphere.
RegionLayout lay_out_regions(const std::vector<RegionSpec>& specs, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary,
                             const tissue::Box& keep_out, const std::string& source);

/// Distance from `p` to the nearest boundary triangle [m]; `normal`, if given, gets that
/// triangle's outward unit normal.
double distance_to_surface(const tissue::Vec3& p, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary,
                           tissue::Vec3* normal = nullptr);

}  // namespace viscera::runtime
