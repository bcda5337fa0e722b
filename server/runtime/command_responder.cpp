#include "viscera/runtime/command_responder.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "viscera/runtime/surface_exit.hpp"

namespace viscera::runtime {

void add_grasp(ContactResult& result, const GraspHold::Reaction& r) {
  result.force_on_tool += r.force_on_tool;
  result.torque_on_tool += r.torque_on_tool;
  result.in_contact = true;
}

ContactProxyParameters proxy_parameters(const SceneSpec& scene, const InstrumentSpec& spec) {
  ContactProxyParameters p;
  p.tip_radius_m = spec.tip_radius_m;
  p.stiffness_n_per_m = scene.contact_stiffness_n_per_m;
  p.damping_s_per_m = scene.contact_damping_s_per_m;
  p.friction = {scene.contact_friction_static, scene.contact_friction_kinetic};
  p.force_limit_n = scene.contact_force_limit_n;
  return p;
}

std::array<double, 9> local_stiffness(const ContactResult& r, ContactCompliance& compliance, bool wait) {
  if (!r.in_contact || r.deepest_triangle[0] < 0) return r.stiffness;
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> coupling(r.stiffness.data());
  const double k_normal = r.normal.dot(coupling * r.normal);
  if (!(k_normal > 0)) return r.stiffness;
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const auto block = wait ? compliance.wait_node(r.deepest_triangle[k]) : compliance.node(r.deepest_triangle[k]);
    if (!block) return r.stiffness;
    C += r.deepest_weights[k] * *block;
  }
  std::array<double, 9> out{};
  const Eigen::Matrix3d K = r.stuck ? Eigen::Matrix3d((Eigen::Matrix3d::Identity() / k_normal + 0.5 * (C + C.transpose())).inverse())
                                    : Eigen::Matrix3d(r.normal * r.normal.transpose() / (1.0 / k_normal + r.normal.dot(C * r.normal)));
  std::size_t next = 0;  // row-major
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[next++] = K(i, j);
  return out;
}

protocol::Force force_message(std::uint32_t instrument_id, std::uint32_t owner, const protocol::Command& command, const ContactResult& r,
                              const std::array<double, 9>& stiffness, std::int64_t server_stamp_ns, std::int64_t step_time_ns) {
  protocol::Force f;
  f.instrument_id = instrument_id;
  f.client_id = owner;
  f.command_seq = command.seq;
  f.command_client_stamp_ns = command.client_stamp_ns;
  f.server_stamp_ns = server_stamp_ns;
  f.step_time_ns = step_time_ns;
  f.force = {r.force_on_tool.x(), r.force_on_tool.y(), r.force_on_tool.z()};
  f.torque = {r.torque_on_tool.x(), r.torque_on_tool.y(), r.torque_on_tool.z()};
  f.in_contact = r.in_contact;
  f.contact_point = {r.point.x(), r.point.y(), r.point.z()};
  f.contact_normal = {r.normal.x(), r.normal.y(), r.normal.z()};
  f.stiffness = stiffness;
  f.penetration_m = r.depth_m;
  f.cutting = r.cutting;
  // At most what a decoder accepts (an average of stretches beyond 10 is an organ past saving).
  f.tip_strain = std::isfinite(r.tip_strain) ? std::min(r.tip_strain, 10.0) : 10.0;
  f.friction_mu = r.in_contact && !r.cutting ? r.friction_mu : 0.0;
  return f;
}

void CommandResponder::set_instruments(const std::vector<InstrumentSpec>& instruments, const std::shared_ptr<const ContactSurface>& surface,
                                       double contact_stiffness_n_per_m) {
  queries_.clear();
  scalpels_.clear();
  for (const auto& s : instruments) {
    queries_[s.id] = std::make_unique<ProbeContact>(surface, s.tip_radius_m, contact_stiffness_n_per_m);
    if (s.kind == InstrumentKind::scalpel) scalpels_.insert(s.id);
  }
}

void CommandResponder::set_surface(const std::shared_ptr<const ContactSurface>& surface) {
  for (auto& [id, q] : queries_) q->set_surface(surface);
}

void CommandResponder::publish(std::shared_ptr<const Snapshot> snapshot) {
  std::lock_guard lock(mutex_);
  snapshot_ = std::move(snapshot);
}

std::shared_ptr<const Snapshot> CommandResponder::latest() const {
  std::lock_guard lock(mutex_);
  return snapshot_;
}

ContactResult CommandResponder::answer(std::uint32_t instrument_id, const protocol::Command& c, std::shared_ptr<const Snapshot>* used) const {
  const auto snap = latest();
  if (used) *used = snap;
  const Vec3 commanded(c.tip_position[0], c.tip_position[1], c.tip_position[2]);
  const auto held = snap->tool_position.find(instrument_id);
  // Answered where the tool can be after the next tick: the commanded tip, unless the tool lags
  // it by more than a tick's reach at the scene's speed limit (just claimed with the device deep
  // in the organ, a hand faster than the limit): then as far toward it as the tool can go. The
  // commanded tip itself gave the contact's whole depth at once (14.5 N in one answer after the
  // 12k liver was loaded under a holding probe) while the server's tool entered from outside.
  // A paused organ's tools do not move: its answers are at the commanded tip (a wall).
  // Not active when the snapshot was taken (claimed since): the server starts it outside the
  // tissue, so it touches nothing yet.
  if (held == snap->tool_position.end()) return ContactResult{};
  Vec3 tip = commanded;
  if (!snap->paused)
    if (const Vec3 gap = commanded - held->second; gap.norm() > snap->tool_reach_m) tip = held->second + (snap->tool_reach_m / gap.norm()) * gap;
  if (scalpels_.contains(instrument_id) && ((c.buttons & kCutButton) != 0 || snap->pressed_through.contains(instrument_id)))
    return ContactResult{.cutting = true};  // cutting: the blade passes through
  if (snap->in_cut.contains(instrument_id)) return ContactResult{};  // leaving the cut: it touches nothing
  const ProbeContact& query = *queries_.at(instrument_id);
  const auto proxy = snap->proxies.find(instrument_id);
  ContactResult result = proxy != snap->proxies.end() ? proxy->second.query(tip, snap->x) : query.query(tip, snap->x);
  if (snap->paused && !result.in_contact) {
    const Vec3 back = held->second - tip;
    result = contact_from_inside(query, snap->x, tip, back.norm() > 1e-9 ? Vec3(back.normalized()) : Vec3::UnitZ());
  }
  if (const auto g = snap->grasped.find(instrument_id); g != snap->grasped.end() && !g->second.empty()) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(c.orientation[0], c.orientation[1], c.orientation[2], c.orientation[3]).normalized();
    add_grasp(result, g->second.query(tip, q, snap->x));
  }
  // The strain the last tick left at the instrument, while the commanded pose still touches.
  if (const auto s = snap->tip_strain.find(instrument_id); result.in_contact && s != snap->tip_strain.end()) result.tip_strain = s->second;
  return result;
}

}  // namespace viscera::runtime
