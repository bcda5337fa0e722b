#include "grasp_hold.hpp"

namespace viscera::runtime {

GraspHold::GraspHold(const Vec3& tip, const Eigen::Quaterniond& tool, std::span<const std::int32_t> candidates, std::span<const Vec3> x,
                     double radius_m, double stiffness_n_per_m)
    : stiffness_(stiffness_n_per_m) {
  const Eigen::Matrix3d to_tool = tool.toRotationMatrix().transpose();
  for (const auto n : candidates)
    if ((x[n] - tip).norm() < radius_m) held_.emplace_back(n, to_tool * (x[n] - tip));
}

GraspHold::Reaction GraspHold::apply(const Vec3& tip, const Eigen::Quaterniond& tool, std::span<const Vec3> x, std::span<Vec3> f,
                                     std::span<double> node_stiffness) const {
  const Eigen::Matrix3d R = tool.toRotationMatrix();
  Reaction r;
  for (const auto& [node, local] : held_) {
    const Vec3 arm = R * local;                              // from the tip to the node's anchor
    const Vec3 pull = stiffness_ * (tip + arm - x[node]);   // on the node
    if (!f.empty()) f[node] += pull;
    if (!node_stiffness.empty()) node_stiffness[node] += stiffness_;
    r.force_on_tool -= pull;
    r.torque_on_tool -= arm.cross(pull);
  }
  return r;
}

}  // namespace viscera::runtime
