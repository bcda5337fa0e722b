#pragma once  // SPDX-License-Identifier: Apache-2.0
// The tissue held by a grasper's closed jaws (docs/HAPTICS.md, "Grasper"): the surface nodes within the
// grasp radius of the tip when the jaws closed, each tied by a spring of stiffness k to the point
// it had in the tool's frame then. The points move and turn with the tool, so lifting pulls the
// tissue and twisting the tool twists it; the tool feels the springs' reaction as a force and as a
// torque about its tip.
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::runtime {

using tissue::Vec3;

class GraspHold {
 public:
  GraspHold() = default;
  /// Grasps the nodes among `candidates` whose positions x lie within `radius_m` of the tip, for a
  /// tool at `tip` with orientation `tool` (tool frame to world).
  GraspHold(const Vec3& tip, const Eigen::Quaterniond& tool, std::span<const std::int32_t> candidates, std::span<const Vec3> x, double radius_m,
            double stiffness_n_per_m);

  bool empty() const { return held_.empty(); }
  std::size_t size() const { return held_.size(); }
  /// The held nodes' mean position in `rest` (the organ's rest shape); needs a node held.
  Vec3 mean_of(std::span<const Vec3> rest) const {
    Vec3 sum = Vec3::Zero();
    for (const auto& [node, anchor] : held_) sum += rest[static_cast<std::size_t>(node)];
    return sum / static_cast<double>(held_.size());
  }

  struct Reaction {
    Vec3 force_on_tool = Vec3::Zero();  ///< [N]
    Vec3 torque_on_tool = Vec3::Zero();  ///< about the tip [N m]
  };
  /// The springs' forces on the organ during one explicit step (the integrator's force field,
  /// tissue::BoundaryConditions::FieldEvaluation) for the tool at (tip, tool) moving at
  /// tool_velocity: each spring at the extension predicted for the end of the step (backward Euler;
  /// its anchor moves with the tip, the tool's turn within one step neglected), added to field.f,
  /// k to field.stiffness. Returns the reaction on the tool.
  Reaction apply(const Vec3& tip, const Eigen::Quaterniond& tool, const Vec3& tool_velocity,
                 const tissue::BoundaryConditions::FieldEvaluation& field) const;
  /// The reaction for the tool at (tip, tool) on the organ at x, changing nothing.
  Reaction query(const Vec3& tip, const Eigen::Quaterniond& tool, std::span<const Vec3> x) const {
    return apply(tip, tool, Vec3::Zero(), {x, {}, {}, {}, {}, 0.0});
  }

 private:
  std::vector<std::pair<std::int32_t, Vec3>> held_;  // node, its point in the tool frame
  double stiffness_ = 0;
};

}  // namespace viscera::runtime
