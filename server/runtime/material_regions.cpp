#include "viscera/runtime/material_regions.hpp"  // SPDX-License-Identifier: Apache-2.0

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
constexpr double kFacingCos = 0.5;  // the nearest surface faces within 60 degrees of `facing`

Vec3 centroid(const tissue::TetMesh& mesh, std::size_t e) {
  const auto& t = mesh.tets[e];
  return 0.25 * (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]] + mesh.nodes[t[3]]);
}

double distance_to_box(const Vec3& p, const Box& b) { return (p.cwiseMax(b.lo).cwiseMin(b.hi) - p).norm(); }

Vec3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

std::string field(std::size_t k, const std::string& rest) { return "organ.regions[" + std::to_string(k) + "]" + rest; }

/// Whether p lies in an element of the mesh. An element whose bounding box does not hold p is
/// passed over without solving for p's barycentric coordinates (a sphere's centre is drawn up to
/// kDraws times, each draw tried against every element).
bool inside(const tissue::TetMesh& mesh, const Vec3& p) {
  for (const auto& t : mesh.tets) {
    const Vec3& a = mesh.nodes[t[0]];
    const Vec3 lo = a.cwiseMin(mesh.nodes[t[1]]).cwiseMin(mesh.nodes[t[2]]).cwiseMin(mesh.nodes[t[3]]);
    const Vec3 hi = a.cwiseMax(mesh.nodes[t[1]]).cwiseMax(mesh.nodes[t[2]]).cwiseMax(mesh.nodes[t[3]]);
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
    Eigen::Matrix3d M;
    M << mesh.nodes[t[1]] - a, mesh.nodes[t[2]] - a, mesh.nodes[t[3]] - a;
    const Vec3 w = M.partialPivLu().solve(p - a);
    if (w.minCoeff() >= 0 && w.sum() <= 1) return true;
  }
  return false;
}

/// A uniform number in [0, 1) from 53 bits of a draw.
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// A sphere's centre drawn from its seed: points uniform in the organ's bounding box from a 64-bit
/// Mersenne twister (x, y, z from three draws), the first inside the organ that qualifies.
PlacedRegion draw_sphere(const RegionSpec& spec, std::size_t k, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary,
                         const Box& keep_out, const std::string& source) {
  std::mt19937_64 rng(spec.seed);
  const Box bounds = tissue::bounding_box(mesh);
  for (int draw = 0; draw < kDraws; ++draw) {
    Vec3 c;
    for (int a = 0; a < 3; ++a) c[a] = bounds.lo[a] + unit(rng) * (bounds.hi[a] - bounds.lo[a]);
    if (distance_to_box(c, keep_out) <= spec.radius_m || !inside(mesh, c)) continue;
    Vec3 normal;
    const double depth = distance_to_surface(c, mesh, boundary, &normal) - spec.radius_m;
    if (depth < spec.min_depth_m || depth > spec.max_depth_m) continue;
    if (vec(spec.facing).squaredNorm() > 0 && normal.dot(vec(spec.facing)) < kFacingCos) continue;
    PlacedRegion r;
    r.center_m = c;
    r.depth_m = depth;
    return r;
  }
  throw InputError(source, 0, field(k, ".sphere.random_center.depth_m"),
                   "no place in the organ takes a sphere of radius " + std::to_string(spec.radius_m) + " m with its top " +
                       std::to_string(spec.min_depth_m) + "-" + std::to_string(spec.max_depth_m) + " m deep" +
                       (vec(spec.facing).squaredNorm() > 0 ? " under a surface facing the stated way" : "") + ", clear of the fixed slab (" +
                       std::to_string(kDraws) + " centres tried)");
}

const char* shape_field(RegionSpec::Shape shape) {
  switch (shape) {
    case RegionSpec::Shape::box: return ".box";
    case RegionSpec::Shape::elements: return ".elements";
    case RegionSpec::Shape::sphere: break;
  }
  return ".sphere";
}

/// A tagged element set's region: its elements take the region's material; it is described by
/// the bounding box of their nodes and their volume-weighted centroid.
PlacedRegion tagged_region(const RegionSpec& spec, std::size_t k, const tissue::TetMesh& mesh, std::vector<std::uint16_t>& material_of_tet,
                           const std::string& source) {
  const tissue::ElementSet* set = tissue::find_element_set(mesh, spec.element_set);
  if (!set) {
    const std::string known = tissue::describe_element_sets(mesh);
    throw InputError(source, 0, field(k, ".elements"),
                     "'" + common::printable(spec.element_set) + "' is not a physical group of the organ's mesh (" +
                         (known.empty() ? "it tags no volume elements" : "its volume groups: " + known) + ")");
  }
  PlacedRegion r;
  r.box = {Vec3::Constant(std::numeric_limits<double>::infinity()), Vec3::Constant(-std::numeric_limits<double>::infinity())};
  Vec3 weighted = Vec3::Zero();
  double volume = 0;
  for (const std::int32_t e : set->tets) {
    material_of_tet[e] = static_cast<std::uint16_t>(k + 1);
    const auto& t = mesh.tets[e];
    for (const std::int32_t n : t) {
      r.box.lo = r.box.lo.cwiseMin(mesh.nodes[n]);
      r.box.hi = r.box.hi.cwiseMax(mesh.nodes[n]);
    }
    const double v = tissue::signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    weighted += v * centroid(mesh, e);
    volume += v;
  }
  r.center_m = volume > 0 ? Vec3(weighted / volume) : Vec3(0.5 * (r.box.lo + r.box.hi));
  return r;
}

}  // namespace

double distance_to_surface(const Vec3& p, const tissue::TetMesh& mesh, const tissue::BoundarySurface& boundary, Vec3* normal) {
  double best2 = std::numeric_limits<double>::infinity();
  for (const auto& t : boundary.triangles) {
    Vec3 w;
    const Vec3 &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]];
    const double d2 = (closest_point_on_triangle(p, a, b, c, &w) - p).squaredNorm();
    if (d2 < best2) {
      best2 = d2;
      if (normal) *normal = (b - a).cross(c - a).normalized();
    }
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
    if (spec.shape == RegionSpec::Shape::elements) {
      r = tagged_region(spec, k, mesh, out.material_of_tet, source);
    } else if (spec.shape == RegionSpec::Shape::box) {
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
    if (spec.shape != RegionSpec::Shape::elements)  // a tagged set took its elements above
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
      throw InputError(source, 0, field(k, shape_field(specs[k].shape)),
                       "'" + specs[k].name + "' holds no element of the organ (" +
                           (specs[k].shape == RegionSpec::Shape::elements ? "its set is empty" : "no element's centroid lies inside it") +
                           (k + 1 < specs.size() ? ", or later regions took them all)" : ")"));
  return out;
}

}  // namespace viscera::runtime
