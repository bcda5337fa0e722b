#include "viscera/client/local_force_model.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace viscera::client {

RenderedForce render_local_model(const protocol::Force& f, const protocol::Vector3& x0, const protocol::Vector3& x, double max_force_n) {
  RenderedForce r;
  if (!f.in_contact) return r;
  const double dx[3] = {x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]};
  for (int i = 0; i < 3; ++i) {
    r.force[i] = f.force[i];
    for (int j = 0; j < 3; ++j) r.force[i] -= f.stiffness[3 * i + j] * dx[j];
  }
  // Push only: a force that would pull the tool into the tissue is no contact.
  const auto& n = f.contact_normal;
  const double normal = r.force[0] * n[0] + r.force[1] * n[1] + r.force[2] * n[2];
  if (normal <= 0) return RenderedForce{};
  // Coulomb: a model with friction holds sideways at most mu times its push (a stuck tool's model
  // is stiff in every direction; moved far along the surface, it slides at the cone).
  if (f.friction_mu > 0) {
    double t[3], tangential = 0;
    for (int i = 0; i < 3; ++i) {
      t[i] = r.force[i] - normal * n[i];
      tangential += t[i] * t[i];
    }
    tangential = std::sqrt(tangential);
    if (const double cone = f.friction_mu * normal; tangential > cone)
      for (int i = 0; i < 3; ++i) r.force[i] = normal * n[i] + t[i] * (cone / tangential);
  }
  const double mag = std::sqrt(r.force[0] * r.force[0] + r.force[1] * r.force[1] + r.force[2] * r.force[2]);
  if (mag > max_force_n) {
    for (double& c : r.force) c *= max_force_n / mag;
    r.clamped = true;
  }
  return r;
}

void LocalForceRenderer::update(const protocol::Force& f, const protocol::Vector3& x0, double t_s) {
  const double g = gain(t_s);
  if (g < 1) {  // the server answers again after a fade: fade back in from where the force is
    resume_s_ = t_s;
    resume_gain_ = g;
  }
  lost_s_ = std::numeric_limits<double>::infinity();
  // A contact regained with force is a jump (the first model after a claim is restarted by the
  // device loop, restart_at_next_model()).
  const bool regained = f.in_contact && has_new_ && !new_.force.in_contact &&
                        std::sqrt(f.force[0] * f.force[0] + f.force[1] * f.force[1] + f.force[2] * f.force[2]) > fade_.contact_onset_n;
  if (has_new_) {
    old_ = new_;
    has_old_ = true;
  }
  new_ = {f, x0};
  has_new_ = true;
  arrived_s_ = t_s;
  if (regained || std::exchange(restart_pending_, false)) restart(t_s);
}

void LocalForceRenderer::restart(double t_s) {
  jump_s_ = t_s;
  jump_from_ = last_rendered_;
}

void LocalForceRenderer::server_lost(double t_s) { lost_s_ = std::min(lost_s_, t_s); }

double LocalForceRenderer::fade_start_s() const {
  return std::min(lost_s_, has_new_ ? arrived_s_ + fade_.stale_after_s : std::numeric_limits<double>::infinity());
}

double LocalForceRenderer::gain(double t_s) const {
  const double rate = fade_.fade_s > 0 ? 1.0 / fade_.fade_s : std::numeric_limits<double>::infinity();
  // Fading back in after a model came while fading out, and fading out once the models stop.
  const double in = std::min(1.0, resume_gain_ + rate * std::max(0.0, t_s - resume_s_));
  const double start = fade_start_s();
  if (t_s <= start) return in;
  const double at_start = std::min(1.0, resume_gain_ + rate * std::max(0.0, start - resume_s_));
  return std::max(0.0, at_start - rate * (t_s - start));
}

RenderedForce LocalForceRenderer::render(const protocol::Vector3& x, double t_s) {
  if (!has_new_) return {};
  constexpr double kUnlimited = std::numeric_limits<double>::infinity();
  const auto now = render_local_model(new_.force, new_.x0, x, kUnlimited);
  const double a = blend_ > 0 && has_old_ ? std::clamp((t_s - arrived_s_) / blend_, 0.0, 1.0) : 1.0;
  RenderedForce r = now;
  if (a < 1.0) {
    const auto before = render_local_model(old_.force, old_.x0, x, kUnlimited);
    for (int i = 0; i < 3; ++i) r.force[i] = a * now.force[i] + (1 - a) * before.force[i];
  }
  const double mag = std::sqrt(r.force[0] * r.force[0] + r.force[1] * r.force[1] + r.force[2] * r.force[2]);
  if (mag > max_force_) {
    for (double& c : r.force) c *= max_force_ / mag;
    r.clamped = true;
  }
  const double g = gain(t_s);
  for (double& c : r.force) c *= g;
  if (jump_s_ >= 0) {  // after a jump: from the force the hand felt to this one
    const double a = fade_.fade_in_s > 0 ? std::clamp((t_s - jump_s_) / fade_.fade_in_s, 0.0, 1.0) : 1.0;
    for (int i = 0; i < 3; ++i) r.force[i] = a * r.force[i] + (1 - a) * jump_from_[i];
    if (a >= 1) jump_s_ = -1;
  }
  last_rendered_ = r.force;
  return r;
}

double LocalForceRenderer::model_age_s(double t_s) const { return has_new_ ? t_s - arrived_s_ : std::numeric_limits<double>::infinity(); }

}  // namespace viscera::client
