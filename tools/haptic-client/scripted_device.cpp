#include "scripted_device.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include "say.hpp"

namespace viscera::haptic {

ScriptedDevice::ScriptedDevice(std::string script, const protocol::Scene& scene, double duration_s, double depth_m, double pull_m, double hold_s,
                               double force_n, double length_m, double offset_y_m)
    : script_(std::move(script)),
      cx_(0.5 * (scene.bounds_min[0] + scene.bounds_max[0])),
      cy_(0.5 * (scene.bounds_min[1] + scene.bounds_max[1]) + (script_ == "incise" ? offset_y_m : 0.0)),
      top_(scene.bounds_max[2]),
      bottom_(scene.bounds_min[2]),
      duration_(duration_s),
      depth_(depth_m),
      pull_(pull_m),
      hold_(hold_s),
      target_force_(force_n),
      length_(length_m),
      // Search: down from 1 cm above the organ at a speed that reaches its bottom in 40% of the run.
      search_speed_((top_ + 0.01 - bottom_) / (0.4 * duration_s)) {}

client::DeviceSample ScriptedDevice::read(double t) {
  t_ = t;
  double jaw = 0.5;
  const bool incise = script_ == "incise";
  double x = incise ? cx_ - 0.5 * length_ : cx_;
  std::uint32_t buttons = 0;
  if (std::isnan(contact_z_)) {  // searching for the surface (it sags under gravity, moves under other tools)
    z_ = std::max(bottom_, top_ + 0.01 - search_speed_ * t);
  } else if (script_ == "press") {
    const double mid = std::max(0.5 * duration_, contact_t_ + 1e-3);
    z_ = t < mid ? contact_z_ - depth_ * (t - contact_t_) / (mid - contact_t_) : contact_z_ - depth_ * (duration_ - t) / (duration_ - mid);
  } else if (incise) {  // plunge, draw, rise; the cut button held from contact to the end
    const double t1 = contact_t_ + 0.2, t3 = std::max(duration_ - 0.1, t1 + 0.2), t2 = t3 - 0.2;
    const double draw = std::clamp((t - t1) / std::max(t2 - t1, 1e-3), 0.0, 1.0);
    x += length_ * draw;
    z_ = t < t1 ? contact_z_ - depth_ * (t - contact_t_) / 0.2 : t < t2 ? contact_z_ - depth_ : contact_z_ - depth_ * std::max(0.0, (t3 - t) / 0.2);
    buttons = t < duration_ - 0.05 ? 1u : 0u;
  } else if (script_ == "hold") {
    // Deeper while the force is below the target, back while above: dz/dt = -g (F* - F), with g
    // giving a time constant of about 0.3 s on soft tissue (about 100 N/m under the probe).
    constexpr double kGain = 0.03;  // [m/(N s)]
    const double dt = std::clamp(t - hold_t_, 0.0, 0.01);
    hold_t_ = t;
    if (hold_z_ == 0) hold_z_ = contact_z_;
    hold_z_ -= kGain * (target_force_ - force_) * dt;
    z_ = std::min(hold_z_, contact_z_ + 0.005);
  } else if (hold_ >= 0) {  // grasp, pull at 1 cm/s, hold, open
    const double bite = contact_z_ - depth_, t1 = contact_t_ + 0.3, t2 = t1 + pull_ / 0.01, t3 = t2 + hold_;
    if (t < t1)
      z_ = contact_z_ - depth_ * (t - contact_t_) / (t1 - contact_t_);
    else
      z_ = bite + pull_ * std::min(1.0, (t - t1) / (t2 - t1));
    jaw = t < t3 ? 0.0 : 0.5;
  } else {  // grasp
    const double bite = contact_z_ - depth_, t1 = contact_t_ + 0.05 * duration_, t2 = std::max(0.75 * duration_, t1 + 1e-3);
    if (t < t1)
      z_ = contact_z_ - depth_ * (t - contact_t_) / (t1 - contact_t_);
    else if (t < t2)
      z_ = bite + pull_ * (t - t1) / (t2 - t1);
    else
      z_ = bite + pull_;
    jaw = t < t2 ? 0.0 : 0.5;
  }
  return {{x, cy_, z_}, jaw, buttons, t >= duration_};
}

void ScriptedDevice::render(const protocol::Vector3& force_n, bool in_contact) {
  force_ = std::sqrt(force_n[0] * force_n[0] + force_n[1] * force_n[1] + force_n[2] * force_n[2]);
  if (std::isnan(contact_z_) && in_contact) {
    contact_z_ = z_;
    contact_t_ = t_;
    say("t = %5.2f s  contact at tip z %.4f m", t_, z_);
  }
}

}  // namespace viscera::haptic
