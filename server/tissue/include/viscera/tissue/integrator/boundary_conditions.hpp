#pragma once  // SPDX-License-Identifier: Apache-2.0
// Loads and constraints shared by the integrators: lumped masses, gravity, fixed nodes and nodes
// whose position is prescribed as a function of rest position and time.
#include <functional>
#include <span>
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Lumped nodal masses [kg]: each tetrahedron gives a quarter of rho V to each vertex.
std::vector<double> lumped_masses(const TetMesh& mesh, std::span<const double> density_kg_m3);
std::vector<double> lumped_masses(const TetMesh& mesh, double density_kg_m3);

struct PrescribedMotion {
  std::vector<std::int32_t> nodes;
  /// Position [m] of a node with rest position X at time t [s].
  std::function<Vec3(const Vec3& rest, double t)> position;
};

/// One coordinate of one node held at its rest value (a roller or symmetry plane).
struct AxisConstraint {
  std::int32_t node;
  int axis;  ///< 0 = x, 1 = y, 2 = z
};

/// One coordinate of a set of nodes moved as prescribed, the others free (a frictionless grip).
struct PrescribedAxisMotion {
  std::vector<std::int32_t> nodes;
  int axis = 0;
  /// Coordinate [m] of a node with rest position X at time t [s].
  std::function<double(const Vec3& rest, double t)> coordinate;
};

struct BoundaryConditions {
  Vec3 gravity_m_s2 = Vec3::Zero();
  std::vector<std::int32_t> fixed_nodes;  ///< held at their rest positions
  std::vector<AxisConstraint> fixed_axes;  ///< single coordinates held at rest
  std::vector<PrescribedMotion> prescribed;  ///< moved as prescribed
  std::vector<PrescribedAxisMotion> prescribed_axes;  ///< one coordinate moved as prescribed
  /// External forces [N] per node (empty = none), scaled by force_amplitude(t) if given.
  std::vector<Vec3> nodal_forces;
  std::function<double(double t)> force_amplitude;

  /// A force field added at every explicit force evaluation (contact with an instrument):
  /// f += field(x, v). It also adds per node a bound on its own stiffness there (`stiffness`
  /// [N/m], at least the Gershgorin row sum of -df/dx) and on its damping (`damping` [N s/m], the
  /// same for -df/dv); the explicit integrator treats those parts implicitly, so the field never
  /// limits the step. Explicit integrator only.
  ///
  /// Springs: a field evaluates each spring at the extension predicted for the end of the step,
  /// k (e + dt_s de/dt) with the rate from v (relative to whatever the spring is anchored to), and
  /// reports k in `stiffness`. The integrator's update (m + dt^2 k) v' = (m + dt^2 k) v + dt f
  /// then reads (m + dt^2 k) v' = m v + dt (f_other - k e): backward Euler in the spring, which
  /// only removes energy, also when springs come and go from one step to the next (contact). A
  /// spring taken at its current extension alone is integrated with the added mass dt^2 k only:
  /// stable while it stays, but when contact switches on and off at the step's time scale the
  /// changing mass pumps energy into the surface (seen on the 12k liver with mass scaling).
  struct FieldEvaluation {
    std::span<const Vec3> x, v;  ///< positions [m], velocities [m/s]
    std::span<Vec3> f;  ///< forces to add to [N]
    std::span<double> stiffness;  ///< per node [N/m]
    std::span<double> damping;  ///< per node [N s/m]
    double dt_s = 0.0;  ///< the step these forces will be integrated over [s]
  };

  std::function<void(const FieldEvaluation&)> force_field;

  /// 1 for each coordinate (3 per node) that is fixed or prescribed, else 0.
  std::vector<char> constrained_mask(std::size_t node_count) const;
  /// External force on node i at time t (gravity excluded).
  Vec3 nodal_force(std::size_t i, double t) const {
    if (nodal_forces.empty()) return Vec3::Zero();
    return force_amplitude ? Vec3(force_amplitude(t) * nodal_forces[i]) : nodal_forces[i];
  }
};

/// The constraints of nodes a cut made (MeshEdit::new_nodes, numbered from `nodes_before`, each
/// at (1 - t) x[a] + t x[b], a copy when a = b; a node may come from one made before it): a new
/// node is held as both its ends are, fixed when both are fixed, an axis held when both hold it,
/// moved with a prescribed motion when both are; it carries no nodal force.
struct NewNodeEnds {
  std::int32_t a = 0, b = 0;
};
void extend_constraints(BoundaryConditions& bc, std::span<const NewNodeEnds> new_nodes, std::size_t nodes_before);

/// Node selections for fixed regions.
std::vector<std::int32_t> nodes_in_box(const TetMesh& mesh, const Box& box);
/// Boundary-surface nodes inside the box.
std::vector<std::int32_t> surface_nodes_in_box(const TetMesh& mesh, const Box& box);

}  // namespace viscera::tissue
