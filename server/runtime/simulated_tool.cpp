#include "viscera/runtime/simulated_tool.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::runtime {

Eigen::Quaterniond SimulatedTool::orientation() const {
  const auto& q = command_.orientation;
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
}

bool SimulatedTool::begin_tick(bool active, std::uint32_t owner, const protocol::Command& command) {
  const bool was_active = active_;
  active_ = active;
  owner_ = owner;
  if (!active_) {
    held_ = {};  // released, or its client silent: a grasper lets go
    press_ = {};
    leaving_ = false;
    return false;
  }
  if (was_active && blade_cuts(spec_, command_) && !blade_cuts(spec_, command)) leaving_ = true;
  command_ = command;
  if (was_active) return false;
  position_ = Vec3(command.tip_position[0], command.tip_position[1], command.tip_position[2]);
  velocity_ = Vec3::Zero();
  return true;
}

void SimulatedTool::move(double dt_s, double max_speed_m_s) {
  if (!active_) return;
  const auto& p = command_.tip_position;
  const Vec3 gap = Vec3(p[0], p[1], p[2]) - position_;
  const double reach = max_speed_m_s * dt_s, d = gap.norm();
  const Vec3 step = d <= reach ? gap : Vec3((reach / d) * gap);
  position_ += step;
  velocity_ = step / dt_s;
}

ToolEvent SimulatedTool::update_grasp(std::span<const std::int32_t> surface, std::span<const Vec3> x, double grasp_stiffness_n_per_m) {
  if (!active_ || spec_.kind != InstrumentKind::grasper) return ToolEvent::none;
  if (held_.empty() && command_.jaw_opening < kJawGraspBelowRad) {
    held_ = GraspHold(position_, orientation(), surface, x, spec_.grasp_radius_m, grasp_stiffness_n_per_m);
    return held_.empty() ? ToolEvent::none : ToolEvent::grasped;
  }
  if (!held_.empty() && command_.jaw_opening > kJawReleaseAboveRad) {
    held_ = {};
    return ToolEvent::let_go;
  }
  return ToolEvent::none;
}

void SimulatedTool::update_press_through(const ContactResult& contact) {
  if (!active_ || spec_.kind != InstrumentKind::scalpel || !(spec_.cut_force_n > 0)) {
    press_ = {};
    return;
  }
  if (press_.through) {
    if ((position_ - press_.entry_point).dot(press_.entry_normal) > spec_.tip_radius_m) press_ = {};
    return;
  }
  if (contact.in_contact && contact.force_on_tool.norm() >= spec_.cut_force_n) press_ = {true, contact.point, contact.normal};
}

ToolEvent SimulatedTool::update_contact(bool touching, double sim_time_s) {
  touching = touching && active_;
  if (touching) {
    const bool started = !touching_;
    touching_ = true;
    last_touch_s_ = sim_time_s;
    return started ? ToolEvent::contact_started : ToolEvent::none;
  }
  if (touching_ && (!active_ || sim_time_s - last_touch_s_ > kContactEndAfterS)) {
    touching_ = false;
    return ToolEvent::contact_ended;
  }
  return ToolEvent::none;
}

}  // namespace viscera::runtime
