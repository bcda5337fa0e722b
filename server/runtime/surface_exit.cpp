#include "viscera/runtime/surface_exit.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <limits>

namespace viscera::runtime {

namespace {
/// Where the ray p + s d (s > 0) crosses triangle (a, b, c), as s and the barycentric (u, v) of b
/// and c (Moeller and Trumbore 1997); nullopt if it does not.
std::optional<std::array<double, 3>> ray_crossing(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return std::nullopt;  // parallel to the triangle's plane
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3 q = s.cross(e1);
  const double v = inv * d.dot(q);
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = inv * e2.dot(q);
  if (!(t > 0)) return std::nullopt;
  return std::array<double, 3>{t, u, v};
}
}  // namespace

bool inside_surface(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p) {
  // A direction of no symmetry of a mesh (not along an axis or a diagonal), so the ray rarely
  // meets an edge or a vertex exactly.
  static const Vec3 d = Vec3(0.3141592653589793, 0.2718281828459045, 0.9097959895689501).normalized();
  bool inside = false;
  for (const auto& t : surface.triangles)
    if (ray_crossing(p, d, x[t[0]], x[t[1]], x[t[2]])) inside = !inside;
  return inside;
}

std::optional<SurfaceCrossing> first_crossing(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p, const Vec3& d) {
  std::optional<SurfaceCrossing> first;
  for (const auto& t : surface.triangles) {
    const Vec3 &a = x[t[0]], &b = x[t[1]], &c = x[t[2]];
    const auto hit = ray_crossing(p, d, a, b, c);
    if (!hit || (first && (*hit)[0] >= first->distance_m)) continue;
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    const auto [s, u, v] = *hit;
    first = SurfaceCrossing{s, p + s * d, n.normalized(), t, Vec3(1 - u - v, u, v)};
  }
  return first;
}

std::optional<Vec3> way_out(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p, const Vec3& d, double radius_m) {
  if (!inside_surface(surface, x, p)) return std::nullopt;
  const auto out = first_crossing(surface, x, p, d);
  if (!out) return std::nullopt;
  return Vec3((out->distance_m + radius_m) * d);
}

ContactResult contact_from_inside(const ProbeContact& contact, std::span<const Vec3> x, const Vec3& centre, const Vec3& d) {
  ContactResult r;
  const ContactSurface& surface = *contact.surface();
  if (!inside_surface(surface, x, centre)) return r;
  const auto out = first_crossing(surface, x, centre, d);
  if (!out) return r;
  const double k = contact.stiffness_n_per_m();
  r.in_contact = true;
  r.triangles_in_contact = 1;
  r.depth_m = out->distance_m + contact.tip_radius_m();
  r.point = out->point;
  r.normal = out->normal;
  r.force_on_tool = k * r.depth_m * out->normal;
  r.deepest_triangle = out->triangle;
  r.deepest_weights = out->weights;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.stiffness[3 * i + j] = k * out->normal[i] * out->normal[j];
  return r;
}

}  // namespace viscera::runtime
