#pragma once  // SPDX-License-Identifier: Apache-2.0
// Implicit backward Euler with full Newton iterations (docs/MODEL.md section 2): each step solves
//   r(x) = M (1 + alpha dt) / dt^2 (x - x_n) - M v_n / dt - f_int(x) - f_ext = 0
// on the free degrees of freedom with the symmetrised tangent M (1 + alpha dt) / dt^2 + K(x),
// factorised by CHOLMOD, and a backtracking line search on |r|. Iterates to the stated tolerance
// (never a single linearised step) and reports iterations and residuals. The same machinery
// solves for static equilibrium (-f_int(x) - f_ext = 0).
#include <memory>
#include <span>
#include <vector>

#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/integrator/sparse_cholesky.hpp"
#include "viscera/tissue/integrator/state.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

struct ImplicitOptions {
  double dt_s = 1e-2;
  double mass_damping_per_s = 0.0;
  double relative_tolerance = 1e-8;  ///< |r| <= tol x force scale (see NewtonReport)
  int max_iterations = 50;
  /// |r| at or below this also converges [N] (0: none): the residual that matters to the caller,
  /// where the relative tolerance asks for more than the problem's conditioning gives.
  double absolute_tolerance_n = 0.0;
};

struct NewtonReport {
  int iterations = 0;
  double initial_residual_n = 0.0;  ///< |r| before the first iteration [N]
  double residual_n = 0.0;  ///< |r| at the end [N]
  double force_scale_n = 0.0;  ///< max(|r0|, |f_ext|, |f_int|, k_max |u|_max) [N]: the tolerance is relative to it
  int regularised_factorisations = 0;  ///< tangents that were not positive definite
  bool converged = false;
  bool roundoff_limited = false;  ///< stopped at the floating-point floor above the tolerance
};

class ImplicitIntegrator {
 public:
  ImplicitIntegrator(const ForceModel& model, std::vector<double> density_kg_m3, BoundaryConditions bc, ImplicitOptions options = {});
  ~ImplicitIntegrator();

  /// One backward Euler step of options.dt_s. Throws SimulationError if Newton fails to converge.
  NewtonReport step(State& state);
  /// Static equilibrium at time state.time_s (prescribed motions evaluated then); v is zeroed.
  /// Memory variables are not used: the response is the instantaneous (unrelaxed) one.
  NewtonReport solve_static(State& state);

  /// The static stiffness at configuration x (tangent, constrained coordinates removed),
  /// factorised for compliance(); false if it is not positive definite.
  bool factorize_stiffness(const std::vector<Vec3>& x);
  /// Displacements u = K^-1 f for nodal forces f [N] with the last factorize_stiffness();
  /// constrained coordinates get 0. Several threads must not call it at once.
  void compliance(std::span<const Vec3> f, std::span<Vec3> u);

  /// Follows an edit of the mesh its model holds (a cut; the model follows it first, as
  /// GpsModel::follow_edit): new nodes get interpolated positions and velocities and their ends'
  /// constraints (extend_constraints), new elements their parent's density, the lumped masses are
  /// summed again, and the stiffness's sparsity pattern is analysed again for CHOLMOD. That is the
  /// only time the pattern is analysed after construction (pattern_analyses()): a step refactorises
  /// numerically on the pattern it has.
  void follow_edit(const MeshEdit& edit, State& state);
  /// How often the sparsity pattern was analysed: 1 at construction, +1 per edit followed.
  int pattern_analyses() const { return pattern_analyses_; }

  const std::vector<double>& masses() const { return mass_; }
  /// Internal forces [N] at the state the last step or solve ended in (reactions at constrained
  /// coordinates are their negatives).
  const std::vector<Vec3>& last_internal_forces() const { return force_; }
  const ImplicitOptions& options() const { return options_; }
  void set_dt(double dt_s) { options_.dt_s = dt_s; }

 private:
  void analyse_pattern();  ///< the free dofs, and the stiffness's sparsity pattern for CHOLMOD
  NewtonReport newton(State& state, bool dynamic, const std::vector<Vec3>& x_n, const std::vector<Vec3>& v_n);
  double residual(const std::vector<Vec3>& x, bool dynamic, const std::vector<Vec3>& x_n, const std::vector<Vec3>& v_n, std::vector<double>& r);
  void assemble(const std::vector<Vec3>& x, double mass_scale, double regularisation);
  void apply_constraints(State& state, double t);
  void update_external(double t);

  const ForceModel& model_;
  BoundaryConditions bc_;
  ImplicitOptions options_;
  std::vector<double> density_;  ///< per element [kg/m^3]
  std::vector<double> mass_;
  std::vector<Vec3> external_;
  int pattern_analyses_ = 0;
  std::vector<int> dof_;  // dof of each coordinate (3 per node), -1 if constrained
  int free_dofs_ = 0;
  std::unique_ptr<SparseCholesky> solver_;
  std::vector<long> element_slots_;  // 144 per element: slot of (i, j) or -1
  std::vector<long> diagonal_slots_;
  std::vector<Vec3> force_;
  const std::vector<double>* memory_before_ = nullptr;  // during a dynamic step
  std::vector<double> memory_trial_, memory_accepted_;
  double internal_norm_ = 0.0;
  double stiffness_scale_ =
      0.0;  // largest diagonal entry of the element tangents at rest [N/m]  // |f_int| over free dofs at the last residual evaluation
};

}  // namespace viscera::tissue
