#pragma once  // SPDX-License-Identifier: Apache-2.0
// Contact of a sphere-tipped probe with the organ's boundary triangles (docs/HAPTICS.md, "Probe").
// For every triangle, the closest point q to the tip centre c and the signed distance
// s = (c - q) . n along the triangle's outward normal; the tip penetrates by r - s when s < r
// (at an edge or corner of the triangle, by r - |c - q|: what the sphere overlaps there).
// The contact is one penalty spring k at the deepest penetration d, its force k d shared among
// the touched triangles in proportion to their depths, so it does not depend on how finely the
// surface is meshed. A normal dashpot (Hunt-Crossley: k d (1 + alpha rate)) adds, for each touched
// triangle, alpha k d times its share times its rate of penetration (its contact point's velocity
// relative to the tool, along its normal), never pulling: it damps what the penalty spring and
// the surface's own mass still ring at, above the tissue's viscoelastic band. During a step each
// triangle's spring acts at the depth predicted for the end of the step (its depth plus dt times
// its rate), so the integrator takes it by backward Euler (BoundaryConditions::FieldEvaluation):
// taken at the current depth, contact switching on and off pumped energy into the surface.
// Because s keeps decreasing (and goes negative) when the centre passes below the surface, a tip
// that moved deeper than its radius within one step is still pushed out along the normal: it does
// not tunnel (triangles whose plane is more than `max_depth` behind the tip are ignored, so the
// far side of the organ does not pull). Each triangle's share acts on its vertices with
// barycentric weights; the tool feels the opposite.
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"

namespace viscera::runtime {

using tissue::Vec3;

struct ContactResult {
  Vec3 force_on_tool = Vec3::Zero();  ///< [N]
  /// About the tip centre [N m]: 0 from the sphere's contact (its force passes through the
  /// centre); a grasper's held tissue adds its moment (GraspHold).
  Vec3 torque_on_tool = Vec3::Zero();
  bool in_contact = false;
  Vec3 point = Vec3::Zero(), normal = Vec3::UnitZ();
  std::array<double, 9> stiffness{};  ///< penalty part of -dF/dx [N/m], row-major
  int triangles_in_contact = 0;
  double depth_m = 0;  ///< deepest penetration of the tip sphere [m]
  std::array<std::int32_t, 3> deepest_triangle{-1, -1, -1};  ///< nodes of the deepest contact
  Vec3 deepest_weights = Vec3::Zero();  ///< its barycentric weights
  /// Friction holds the tool where it touches (ContactProxy): its stiffness is isotropic.
  bool stuck = false;
  /// The friction cone the tool is on: static while stuck, kinetic while sliding; 0 without friction.
  double friction_mu = 0;
  /// A scalpel's blade cutting: it passes through the tissue, and touches nothing.
  bool cutting = false;
  /// The tissue's strain within the scene's strain radius of where the instrument touches, after
  /// the tick (tissue::BallStrain; the server sets it, 0 out of contact).
  double tip_strain = 0;
};

/// The boundary triangles a contact looks at, with each one's longest rest edge for the broad
/// phase; immutable once made, so the physics thread's contacts and the command thread's queries
/// share one, and a cut organ swaps in a new one for all of them.
struct ContactSurface {
  std::vector<tissue::Triangle> triangles;
  std::vector<double> longest_rest_edge_m;
  /// The triangles around each node (for vertex normals): those of node i are
  /// incident[incident_begin[i] .. incident_begin[i + 1]); nodes off the surface have none.
  std::vector<std::uint32_t> incident_begin, incident;
};
std::shared_ptr<const ContactSurface> make_contact_surface(std::vector<tissue::Triangle> triangles, std::span<const Vec3> rest);

class ProbeContact {
 public:
  /// rest: the mesh's rest positions, for the broad phase (a triangle is skipped when its first
  /// vertex is farther from the tip than the tip radius, the depth limit and three times its
  /// longest rest edge: an edge stretched beyond 3x fails the integration's strain check first).
  ProbeContact(std::vector<tissue::Triangle> surface, std::span<const Vec3> rest, double tip_radius_m, double stiffness_n_per_m,
               double max_depth_m = 0.02, double damping_s_per_m = 0.0)
      : ProbeContact(make_contact_surface(std::move(surface), rest), tip_radius_m, stiffness_n_per_m, max_depth_m, damping_s_per_m) {}
  ProbeContact(std::shared_ptr<const ContactSurface> surface, double tip_radius_m, double stiffness_n_per_m, double max_depth_m = 0.02,
               double damping_s_per_m = 0.0);
  /// Another surface of the same organ (after a cut); the nodes it names must exist in the
  /// positions the contact is given from now on.
  void set_surface(std::shared_ptr<const ContactSurface> surface) { surface_ = std::move(surface); }
  const std::shared_ptr<const ContactSurface>& surface() const { return surface_; }
  double tip_radius_m() const { return radius_; }
  double stiffness_n_per_m() const { return stiffness_; }
  /// The contact's forces on the organ during one explicit step (the integrator's force field,
  /// tissue::BoundaryConditions::FieldEvaluation): adds the penalty forces to field.f and to
  /// field.stiffness a bound on their stiffness per node, sqrt(3) k share w (the Gershgorin row
  /// sum); with velocities, the dashpot acts too and field.damping gets sqrt(3) alpha k d share w.
  /// Each triangle's spring is taken at the depth predicted for the end of the step,
  /// d + dt_s rate (backward Euler in the spring, as FieldEvaluation asks). Returns the reaction.
  /// Not for concurrent calls on one object (it reuses a scratch list).
  ContactResult apply(const Vec3& centre, const Vec3& tool_velocity, const tissue::BoundaryConditions::FieldEvaluation& field) const;
  /// The reaction for the tip at `centre` on the organ at x, changing nothing: the spring alone
  /// (no velocities, so no dashpot).
  ContactResult query(const Vec3& centre, std::span<const Vec3> x) const { return apply(centre, Vec3::Zero(), {x, {}, {}, {}, {}, 0.0}); }

 private:
  struct Touch {
    std::size_t triangle;
    Vec3 normal, weights, point;
    double depth;
  };
  std::shared_ptr<const ContactSurface> surface_;
  double radius_, stiffness_, max_depth_, damping_;
  mutable std::vector<Touch> touching_;
};

/// Closest point on triangle (a, b, c) to p, with its barycentric coordinates (Ericson 2005, 5.1.5).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3* barycentric);

}  // namespace viscera::runtime
