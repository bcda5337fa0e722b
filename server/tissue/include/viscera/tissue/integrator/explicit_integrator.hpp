#pragma once  // SPDX-License-Identifier: Apache-2.0
// Explicit symplectic Euler (docs/MODEL.md section 2): v += dt M^-1 (f_int + f_ext);
// v *= exp(-alpha dt) (mass-proportional damping, integrated exactly); x += dt v.
// The step is the computed critical step times a safety factor, never a guess.
#include <functional>
#include <vector>

#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/integrator/mass_scaling.hpp"
#include "viscera/tissue/integrator/stable_step.hpp"
#include "viscera/tissue/integrator/state.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

struct ExplicitOptions {
  /// dt = safety x critical step (0 < s <= 1); with a stiff force field, s <= sqrt(3)/2 keeps the
  /// bound (BoundaryConditions::force_field)
  double safety_factor = 0.9;
  double dt_s = 0.0;  ///< if > 0, used instead (for studies; may be unstable)
  double mass_damping_per_s = 0.0;  ///< alpha >= 0 [1/s]
  double max_edge_strain = 2.0;  ///< |dL|/L0 above this means the run went unstable
  /// Critical step from the global estimate (global_time_step) instead of the element bound.
  bool global_stable_step = false;
  /// Selective mass scaling (mass_scaling.hpp): this fraction of the organ's mass is added to the
  /// elements with the shortest critical steps, as inertia only (weight stays m g). 0: none.
  double added_mass_fraction = 0.0;
};

class ExplicitIntegrator {
 public:
  ExplicitIntegrator(const ForceModel& model, std::vector<double> density_kg_m3, BoundaryConditions bc, ExplicitOptions options = {});

  double dt_s() const { return dt_; }
  const StableStep& critical_step() const { return critical_; }
  /// Lumped masses of the inertia [kg] (with the added mass, if any).
  const std::vector<double>& masses() const { return mass_; }
  /// The mass scaling applied (none: no scaled elements, densities as given).
  const MassScaling& mass_scaling() const { return scaling_; }

  /// One step. On instability (edge strain above the limit, or NaN) throws SimulationError naming
  /// the element and the time, and puts `state` back to the last step that passed the check.
  void step(State& state);
  /// Equal sub-steps, each at most dt_s(), until state.time_s has advanced by `duration_s`.
  /// Returns the number of sub-steps. A strain-stiffening model shortens them: each is at most
  /// dt_s() / sqrt(growth), the model's stiffness_growth at the largest edge strain the last force
  /// evaluation saw (with a tenth more as headroom); when it falls below the sub-step, the rest of
  /// the duration is divided anew. Between sub-steps it asks the interruption (if set) and returns
  /// early when it says so, with the state at the last sub-step taken.
  long advance(State& state, double duration_s);
  /// The largest edge strain |L - L0| / L0 that the force evaluations of the last advance() saw
  /// (at the start of each sub-step).
  double max_edge_strain() const { return max_edge_strain_; }
  /// The longest sub-step the model's stiffening allows after the last force evaluation [s]
  /// (dt_s() for a model without stiffening).
  double stiffened_step_s() const;
  /// The edge strain a sub-step's length is chosen for, after one whose force evaluation saw
  /// `edge_strain`: a tenth more (and 0.002) covers its rise over a sub-step where the tissue is
  /// pulled fast.
  static double headroom_strain(double edge_strain) { return 1.1 * edge_strain + 0.002; }
  /// More sub-steps than this per step of dt_s() and the tissue is past what an explicit step can
  /// follow (a run away, not a stiffening organ): advance() throws SimulationError.
  static constexpr double kMaxStiffenedSubSteps = 64;
  /// Asked between the sub-steps of advance(): true stops it (a program that must stop at once).
  void set_interruption(std::function<bool()> interrupted) { interrupted_ = std::move(interrupted); }

  /// How internal forces are evaluated: by default model.add_forces on the calling thread; a caller
  /// may split them over threads (server/runtime/parallel_forces.hpp). It must add the model's
  /// forces to f (up to rounding) and advance the memory as add_forces does. It may leave parts of
  /// the forces for the node loop below to add: between the two the integrator only adds to f (the
  /// force field), and it reads f[i] only in node i's update. Empty: the default.
  using ForceEvaluation = std::function<ForceStats(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory)>;
  void set_force_evaluation(ForceEvaluation evaluation) { evaluate_ = std::move(evaluation); }
  /// How the nodes' update is run: by default on the calling thread; a caller may split [0, n) into
  /// ranges on threads. It must call `update` on ranges that cover [0, n) once each and return when
  /// all are done (each node's update depends on that node alone: the same bits for any split).
  /// Before it calls `update` on a range, it adds to f there what the force evaluation left.
  using NodeLoop = std::function<void(std::size_t n, const std::function<void(std::size_t first, std::size_t last)>& update)>;
  void set_node_loop(NodeLoop loop) { for_nodes_ = std::move(loop); }

  /// The boundary conditions (their force field may be changed between steps).
  BoundaryConditions& boundary_conditions() { return bc_; }
  /// Kinetic energy [J] of a state.
  double kinetic_energy(const State& state) const;
  /// Potential energy of the weights [J] at positions x (zero at the origin), -sum m_i g.x_i.
  double gravity_energy(std::span<const Vec3> x) const;

  /// Follows an edit of the organ's mesh (a cut), after the model followed it
  /// (GpsModel::follow_edit): `state` gains the new nodes, their positions and velocities
  /// interpolated as the nodes were. New elements take their parent's density. A new node is
  /// fixed when it lies between fixed nodes, or copies one. Each changed element whose own step
  /// falls below the organ's element step gets the density that brings it back (local mass
  /// scaling, docs/CUTTING.md), so dt_s() stays valid; a node whose inertia that raises keeps its
  /// momentum, so the edit adds no kinetic energy. Lumped masses change only where elements did.
  /// Returns the inertia added [kg]. Prescribed motions and nodal forces do not reach new nodes.
  double follow_edit(const MeshEdit& edit, State& state);
  /// Every element an edit changes or makes has its own critical step at least this [s]: the
  /// organ's element bound (every element's own step is at least this, kept so through edits),
  /// or, with the global step estimate, the organ's critical step itself (its worst elements'
  /// own steps lie 2-3x below it, and a new element held only to theirs made the cut liver
  /// unstable: the changed elements must not raise the organ's highest frequency).
  double element_step_s() const { return element_step_s_; }

 private:
  void step_with(State& state, double dt);

  const ForceModel& model_;
  BoundaryConditions bc_;
  ExplicitOptions options_;
  std::vector<double> mass_;
  std::vector<double> density_;  // per element, as given (the weight's)
  std::vector<double> weight_;  // lumped mass of density_ per node (what gravity pulls)
  std::vector<char> constrained_;  // per coordinate
  std::vector<Vec3> inv_mass_;  // per coordinate; 0 where constrained
  std::vector<Vec3> gravity_;  // m g per node
  ForceEvaluation evaluate_;
  NodeLoop for_nodes_;
  std::function<bool()> interrupted_;
  MassScaling scaling_;
  StableStep critical_{};
  double dt_;
  std::vector<Vec3> force_, x_prev_, v_prev_;
  std::vector<double> field_stiffness_, field_damping_;
  double t_prev_ = 0.0;
  std::vector<double> grown_;  ///< follow_edit's scratch: inertia added per node, all 0 between edits
  double max_edge_strain_ = 0.0;
  double last_edge_strain_ = 0.0;  // of the last force evaluation, for the next sub-step's length
  double last_step_end_s_ = -1.0;  // the time the last step left its state at
  double element_step_s_ = 0.0;
};

}  // namespace viscera::tissue
