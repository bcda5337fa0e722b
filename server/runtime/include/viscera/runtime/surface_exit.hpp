#pragma once  // SPDX-License-Identifier: Apache-2.0
// The way out of the organ for a point inside it, at any depth. The contact (ProbeContact) looks
// only at triangles within its depth limit of the tip, so that the far side of the organ never
// pulls; a tool that finds itself deeper than that (the organ reset or reloaded under a deep
// press, a paused organ pressed on) is found inside by the parity of a ray's crossings of the
// closed boundary surface, and leaves the way it came: along a direction the caller knows (the
// last contact's normal, back toward where the tool was held, or up), through the first surface
// that direction crosses. The nearest surface point would not do: 35 mm into the middle of the
// 1.5k liver it is on the organ's underside, and a probe pressed from above came out below it.
// O(triangles): for events (a reset, a claim) and for a paused organ's answers, not for every
// contact.
#include <optional>
#include <span>

#include "viscera/runtime/probe_contact.hpp"

namespace viscera::runtime {

/// Whether `p` lies inside the closed surface `surface` over the node positions `x`: an odd
/// number of crossings of a ray from `p`.
bool inside_surface(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p);

/// Where the ray p + s d (s > 0, `d` a unit vector) first crosses the surface.
struct SurfaceCrossing {
  double distance_m = 0;  ///< s
  Vec3 point = Vec3::Zero(), normal = Vec3::UnitZ();  ///< the crossing, and its triangle's outward normal
  tissue::Triangle triangle{};
  Vec3 weights = Vec3::Zero();  ///< barycentric, on `triangle`
};
std::optional<SurfaceCrossing> first_crossing(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p, const Vec3& d);

/// For a sphere of `radius_m` whose centre `p` is inside the surface: the offset along `d` (unit)
/// that takes it out through the first surface `d` crosses, to a radius beyond it; nullopt for a
/// centre outside.
std::optional<Vec3> way_out(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p, const Vec3& d, double radius_m);

/// `contact`'s spring for a tip whose centre is inside the surface beyond the contact's depth
/// limit, on its way out along `d` (unit): at the first surface `d` crosses, along that surface's
/// normal, as deep as the tip is below it (ProbeContact's penalty, nothing shared); no contact for
/// a centre outside.
ContactResult contact_from_inside(const ProbeContact& contact, std::span<const Vec3> x, const Vec3& centre, const Vec3& d);

}  // namespace viscera::runtime
