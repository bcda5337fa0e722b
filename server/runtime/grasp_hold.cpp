#include "viscera/runtime/grasp_hold.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::runtime {

GraspHold::GraspHold(const Vec3& tip, const Eigen::Quaterniond& tool, std::span<const std::int32_t> candidates, std::span<const Vec3> x,
                     double radius_m, double stiffness_n_per_m)
    : stiffness_(stiffness_n_per_m) {
  const Eigen::Matrix3d to_tool = tool.toRotationMatrix().transpose();
  for (const auto n : candidates)
    if ((x[n] - tip).norm() < radius_m) held_.emplace_back(n, to_tool * (x[n] - tip));
}

GraspHold::Reaction GraspHold::apply(const Vec3& tip, const Eigen::Quaterniond& tool, const Vec3& tool_velocity,
                                     const tissue::BoundaryConditions::FieldEvaluation& field) const {
  const Eigen::Matrix3d R = tool.toRotationMatrix();
  const bool moving = !field.v.empty();
  Reaction r;
  for (const auto& [node, local] : held_) {
    const Vec3 arm = R * local;  // from the tip to the node's anchor
    Vec3 stretch = tip + arm - field.x[node];
    if (moving) stretch += field.dt_s * (tool_velocity - field.v[node]);  // at the end of the step
    const Vec3 pull = stiffness_ * stretch;  // on the node
    if (!field.f.empty()) field.f[node] += pull;
    if (!field.stiffness.empty()) field.stiffness[node] += stiffness_;
    r.force_on_tool -= pull;
    r.torque_on_tool -= arm.cross(pull);
  }
  return r;
}

}  // namespace viscera::runtime
