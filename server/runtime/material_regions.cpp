#include "viscera/runtime/material_regions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "viscera/common/input_error.hpp"
#include "viscera/runtime/probe_contact.hpp"
#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::runtime {

using common::InputError;
using tissue::Box;
using tissue::Vec3;

namespace {

constexpr int kDraws = 20000;  // candidate centres tried per drawn sphere before giving up

Vec3 centroid(const tissue::TetMesh& mesh, std::size_t e) {
  const auto& t = mesh.tets[e];
  return 0.25 * (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]] + mesh.nodes[t[3]]);
}

double distance_to_box(const Vec3& p, const Box& b) { return (p.cwiseMax(b.lo).cwiseMin(b.hi) - p).norm(); }

Vec3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

std::string field(std::size_t k, const std::string& rest) { return "organ.regions[" + std::to_string(k) + "]" + rest; }

/// A sphere's centre drawn from its seed: an element's centroid, taken in the order a 64-bit
/// Mersenne twister picks them (index = draw mod element count), the first that qualifies.
PlacedRegion draw_sphere(const RegionSpec& spec, std::size_t k, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary,
                         const Box& keep_out, const std::string& source) {
  std::mt19937_64 rng(spec.seed);
  for (int draw = 0; draw < kDraws; ++draw) {
    const Vec3 c = centroid(mesh, rng() % mesh.tet_count());
    if (distance_to_box(c, keep_out) <= spec.radius_m) continue;
    const double depth = distance_to_surface(c, mesh, boundary) - spec.radius_m;
    if (depth < spec.min_depth_m || depth > spec.max_depth_m) continue;
    PlacedRegion r;
    r.center_m = c;
    r.depth_m = depth;
    return r;
  }
  throw InputError(source, 0, field(k, ".sphere.random_center.depth_m"),
                   "no place in the organ takes a sphere of radius " + std::to_string(spec.radius_m) + " m with its top " +
                       std::to_string(spec.min_depth_m) + "-" + std::to_string(spec.max_depth_m) + " m deep, clear of the fixed slab (" +
                       std::to_string(kDraws) + " centres tried)");
}

}  // namespace

double distance_to_surface(const Vec3& p, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary) {
  double best2 = std::numeric_limits<double>::infinity();
  for (const auto& t : boundary.triangles) {
    Vec3 w;
    best2 = std::min(best2, (closest_point_on_triangle(p, mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], &w) - p).squaredNorm());
  }
  return std::sqrt(best2);
}

RegionLayout lay_out_regions(const std::vector<RegionSpec>& specs, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary,
                             const Box& keep_out, const std::string& source) {
  RegionLayout out;
  if (specs.empty()) return out;
  if (specs.size() >= std::numeric_limits<std::uint16_t>::max()) throw InputError(source, 0, "organ.regions", "too many regions");
  out.material_of_tet.assign(mesh.tet_count(), 0);
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const RegionSpec& spec = specs[k];
    PlacedRegion r;
    if (spec.shape == RegionSpec::Shape::box) {
      r.box = {vec(spec.lo_m), vec(spec.hi_m)};
    } else if (spec.random_center) {
      r = draw_sphere(spec, k, mesh, boundary, keep_out, source);
    } else {
      r.center_m = vec(spec.center_m);
      r.depth_m = distance_to_surface(r.center_m, mesh, boundary) - spec.radius_m;
    }
    r.name = spec.name;
    r.shape = spec.shape;
    r.radius_m = spec.radius_m;
    const double r2 = spec.radius_m * spec.radius_m;
    for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
      const Vec3 c = centroid(mesh, e);
      if (spec.shape == RegionSpec::Shape::box ? r.box.contains(c) : (c - r.center_m).squaredNorm() <= r2)
        out.material_of_tet[e] = static_cast<std::uint16_t>(k + 1);
    }
    out.regions.push_back(r);
  }
  for (std::size_t e = 0; e < mesh.tet_count(); ++e)
    if (const std::uint16_t m = out.material_of_tet[e]) {
      PlacedRegion& r = out.regions[m - 1];
      ++r.elements;
      const auto& t = mesh.tets[e];
      r.volume_m3 += tissue::signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    }
  for (std::size_t k = 0; k < out.regions.size(); ++k)
    if (out.regions[k].elements == 0)
      throw InputError(source, 0, field(k, specs[k].shape == RegionSpec::Shape::box ? ".box" : ".sphere"),
                       "'" + specs[k].name + "' holds no element of the organ (no element's centroid lies inside it" +
                           (k + 1 < specs.size() ? ", or later regions took them all)" : ")"));
  return out;
}

}  // namespace viscera::runtime
