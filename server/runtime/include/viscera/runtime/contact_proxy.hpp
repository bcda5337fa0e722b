#pragma once  // SPDX-License-Identifier: Apache-2.0
// The tool the tissue touches, kept on the tissue's surface (docs/HAPTICS.md, "The contact: a
// proxy on the surface"). A god-object (Zilles and Salisbury 1995) on a deforming surface: the
// device's tip (the goal) goes where the hand puts it; the proxy, a sphere of the tip's radius,
// stays outside the tissue, held at a point of the surface in the tissue's own coordinates (a
// triangle and barycentric weights), so it moves with the tissue it presses. A virtual coupling
// of stiffness k between goal and proxy is the force: on the tool, and, spread over the surface
// nodes under the proxy (a kernel of the tip's radius), on the tissue, which the integrator takes
// as any force field. The proxy never enters the tissue, whatever the depth of the goal, so the
// tool cannot slide off the point it presses or pass through a soft organ.
//   Each tick (track), before the step: a free proxy is the goal, and anchors where the goal's
// sphere first touches the surface; an anchored one lets go when the goal is back out of its
// sphere, sticks while the coupling's tangential force is within the static friction cone
// (mu_s times its normal force: Coulomb), and otherwise slides along the surface toward the goal
// until the tangential force is mu_k times the normal (Salisbury et al.'s friction cone for the
// god-object). Normals are interpolated from the vertex normals (force shading, Morgenbesser and
// Srinivasan 1996), so a slide feels the organ's shape, not its facets.
//   In the step (apply): the normal force k dn, dn the goal's depth behind the proxy along the
// normal, taken at the depth the step ends at (backward Euler, as ProbeContact) with the
// Hunt-Crossley dashpot alpha k dn rate; the tangential force k times the goal's tangential offset,
// at most the friction cone; the whole at most the scene's force limit (the device's).
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "viscera/runtime/probe_contact.hpp"

namespace viscera::runtime {

/// Coulomb friction between an instrument and the tissue [-].
struct Friction {
  double static_mu = 0, kinetic_mu = 0;
};

struct ContactProxyParameters {
  double tip_radius_m = 0.005;
  double stiffness_n_per_m = 200;  ///< the coupling between the goal and the proxy
  double damping_s_per_m = 0;  ///< Hunt-Crossley alpha
  Friction friction;
  double force_limit_n = 15;  ///< on the tool and the tissue, whatever the goal's depth
  double max_depth_m = 0.02;  ///< a free proxy anchors only to surface this close behind the goal
};

/// A point of the surface in the tissue's coordinates.
struct SurfacePoint {
  std::size_t triangle = 0;
  Vec3 weights = Vec3::Zero();  ///< barycentric
  Vec3 point = Vec3::Zero();  ///< where it is on the positions it was found on
};

/// The surface point nearest to `p` among the triangles within `reach` of it; with `facing`, only
/// triangles whose normal is within about 107 degrees of it (not the far wall of a fold).
std::optional<SurfacePoint> nearest_surface_point(const ContactSurface& surface, std::span<const Vec3> x, const Vec3& p, double reach,
                                                  const Vec3* facing = nullptr);

/// The outward normal at barycentric `w` of `triangle`, interpolated from the vertex normals (each
/// the area-weighted mean of its triangles' normals): continuous across edges.
Vec3 smooth_normal(const ContactSurface& surface, std::span<const Vec3> x, std::size_t triangle, const Vec3& w);

class ContactProxy {
 public:
  ContactProxy(std::shared_ptr<const ContactSurface> surface, const ContactProxyParameters& p);

  /// Another surface (a cut): the proxy lets go, and anchors again on the new one.
  void set_surface(std::shared_ptr<const ContactSurface> surface) {
    surface_ = std::move(surface);
    release();
  }
  /// Lets go (organ reset or replaced, the tool cutting or released).
  void release() { anchored_ = false; }
  bool anchored() const { return anchored_; }
  bool sliding() const { return anchored_ && sliding_; }
  const ContactProxyParameters& parameters() const { return p_; }

  /// Once per tick of `dt_s`, before the step: anchors, sticks, slides or lets go for the goal's
  /// tip centre on the organ at x.
  void track(const Vec3& goal, std::span<const Vec3> x, double dt_s);
  /// The coupling's force in one evaluation of the integrator's force field: on the footprint's
  /// nodes (field.f), with its stiffness bound per node (field.stiffness) and, with velocities,
  /// the dashpot's (field.damping). Returns the reaction on the tool.
  ContactResult apply(const Vec3& goal, const Vec3& goal_velocity, const tissue::BoundaryConditions::FieldEvaluation& field) const;
  /// The reaction for the goal on the organ at x, the proxy tracked from where it is, changing
  /// nothing (the spring alone).
  ContactResult query(const Vec3& goal, std::span<const Vec3> x) const;
  /// The proxy's centre on the organ at x (the goal itself while free).
  Vec3 centre(const Vec3& goal, std::span<const Vec3> x) const;

 private:
  void anchor(const SurfacePoint& at, std::span<const Vec3> x);
  Vec3 point(std::span<const Vec3> x) const;  // the anchor on the organ at x
  Vec3 normal(std::span<const Vec3> x) const;  // the footprint's vertex normals, weighted by its shares

  std::shared_ptr<const ContactSurface> surface_;
  ContactProxyParameters p_;
  bool anchored_ = false, sliding_ = false;
  SurfacePoint at_;
  std::vector<std::int32_t> footprint_;  // surface nodes the force acts on
  std::vector<double> share_;  // and their shares (sum 1)
  Vec3 offset_ = Vec3::Zero();  // the anchor minus the footprint's weighted mean, when anchored
  double lift_m_ = 0;  // the proxy below its offset surface at first touch on a corner, fading out
};

}  // namespace viscera::runtime
