#include "palpating_device.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include "say.hpp"

namespace viscera::haptic {

namespace {
constexpr double kTravelSpeed = 0.2, kDescendSpeed = 0.1, kPressSpeed = 0.05, kLiftSpeed = 0.2;  // [m/s]
constexpr double kDwellS = 0.05;  // at DEPTH before the force is noted [s]
constexpr double kSettleS = 0.2, kSettleMeanS = 0.05;  // held at DEPTH / 2; the force is the mean over the hold's end [s]
constexpr double kCoarse = 0.02, kFine = 0.01;  // grid spacings [m]
constexpr double kCentreRadius = 1.5 * kFine;  // the stiff area's centre is weighed over the points this close to the stiffest [m]
constexpr double kMargin = 0.15;  // of the organ's extent kept clear at its sides
constexpr double kSafeForceN = 2.0;  // a press stops here
constexpr double kMinVerticalShare = 0.8;  // F_z / |F| of a press that counts
constexpr double kLateS = 0.005;  // the server's newest answer older than this: hold still [s]

double magnitude(const protocol::Vector3& f) { return std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]); }
}  // namespace

PalpatingDevice::PalpatingDevice(const protocol::Scene& scene, double depth_m, bool verbose)
    : safe_z_(scene.bounds_max[2] + 0.01), bottom_(scene.bounds_min[2]), depth_(depth_m), verbose_(verbose) {
  const double x0 = scene.bounds_min[0], x1 = scene.bounds_max[0], y0 = scene.bounds_min[1], y1 = scene.bounds_max[1];
  const double mx = kMargin * (x1 - x0), my = kMargin * (y1 - y0);
  for (double x = x0 + mx; x <= x1 - mx + 1e-9; x += kCoarse)
    for (double y = y0 + my; y <= y1 - my + 1e-9; y += kCoarse) probes_.push_back({x, y});
  x_ = probes_.empty() ? 0.5 * (x0 + x1) : probes_[0].x;
  y_ = probes_.empty() ? 0.5 * (y0 + y1) : probes_[0].y;
  z_ = safe_z_;
  if (probes_.empty()) phase_ = Phase::done;
}

void PalpatingDevice::add_neighbours(double x, double y, double spacing) {
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      if (i != 0 || j != 0) probes_.push_back({x + i * spacing, y + j * spacing});
}

std::pair<double, double> PalpatingDevice::stiff_centre(const Probe& best) const {
  std::vector<double> felt;
  for (const Probe& p : probes_)
    if (p.force_n >= 0) felt.push_back(p.force_n);
  std::nth_element(felt.begin(), felt.begin() + static_cast<std::ptrdiff_t>(felt.size() / 2), felt.end());
  const double median = felt[felt.size() / 2];
  double w = 0, x = 0, y = 0;
  for (const Probe& p : probes_)
    if (p.force_n > median && std::hypot(p.x - best.x, p.y - best.y) <= kCentreRadius) {
      w += p.force_n - median;
      x += (p.force_n - median) * p.x;
      y += (p.force_n - median) * p.y;
    }
  return w > 0 ? std::pair{x / w, y / w} : std::pair{best.x, best.y};
}

void PalpatingDevice::next_point() {
  phase_ = Phase::travel;
  if (++current_ < probes_.size()) return;
  const auto best = std::max_element(probes_.begin(), probes_.end(), [](const Probe& a, const Probe& b) { return a.force_n < b.force_n; });
  if (best->force_n < 0) {  // no tissue anywhere
    phase_ = Phase::done;
    return;
  }
  if (!refined_) {
    refined_ = true;
    say("palpate: %zu points 2 cm apart, stiffest at (%.3f, %.3f) m with %.3f N; 1 cm around it next", probes_.size(), best->x, best->y,
        best->force_n);
    const double bx = best->x, by = best->y;
    add_neighbours(bx, by, kFine);
    return;
  }
  if (!marking_) {
    marking_ = true;
    const auto [x, y] = stiff_centre(*best);
    say("palpate: stiffest of %zu points at (%.3f, %.3f) m with %.3f N; the stiff area's centre at (%.3f, %.3f) m: marking it", probes_.size(),
        best->x, best->y, best->force_n, x, y);
    probes_.push_back({x, y});
    return;
  }
  phase_ = Phase::done;
}

client::DeviceSample PalpatingDevice::read(double t) {
  const double dt = std::clamp(t - t_, 0.0, 0.01);
  t_ = t;
  if (phase_ == Phase::done) {
    z_ = std::min(safe_z_, z_ + kLiftSpeed * dt);
    return {{x_, y_, z_}, 0.5, 0, z_ >= safe_z_};
  }
  // The server is late (a stalled process, a lost packet): where the tip touches or may touch,
  // going on would press blind; it holds still, and a hold's clock waits for fresh answers.
  const bool touching_phase = phase_ == Phase::descend || phase_ == Phase::press || phase_ == Phase::settle || phase_ == Phase::dwell;
  if (model_age_s_ > kLateS && touching_phase) {
    phase_t_ += dt;
    return {{x_, y_, z_}, 0.5, buttons_, false};
  }
  Probe& p = probes_[current_];
  switch (phase_) {
    case Phase::travel: travel(p, dt); break;
    case Phase::descend: descend(dt); break;
    case Phase::press: press(p, t, dt); break;
    case Phase::settle:
    case Phase::dwell: hold(p, t); break;
    case Phase::lift: lift(dt); break;
    case Phase::done: break;
  }
  return {{x_, y_, z_}, 0.5, buttons_, false};
}

void PalpatingDevice::travel(Probe& p, double dt) {
  if (z_ < safe_z_) {  // straight up first, the way it came down
    z_ = std::min(safe_z_, z_ + kLiftSpeed * dt);
    return;
  }
  const double dx = p.x - x_, dy = p.y - y_, d = std::hypot(dx, dy), step = kTravelSpeed * dt;
  if (d <= step) {
    x_ = p.x;
    y_ = p.y;
    if (z_ >= safe_z_) phase_ = Phase::descend;
  } else {
    x_ += dx / d * step;
    y_ += dy / d * step;
  }
}

void PalpatingDevice::descend(double dt) {
  if (contact_) {
    contact_z_ = z_;
    phase_ = Phase::press;
  } else if (z_ <= bottom_) {
    next_point();  // no tissue under this point
  } else {
    z_ -= kDescendSpeed * dt;
  }
}

void PalpatingDevice::press(Probe& p, double t, double dt) {
  if (magnitude(force_) > kSafeForceN && marking_) {
    // The marking press stops where the tissue pushes back this hard and marks there: touching,
    // and never pressing past the safe force (a CI run marked 4.4 N deep without this stop).
    start_hold(Phase::dwell, t);
    return;
  }
  if (magnitude(force_) > kSafeForceN) {
    // The tissue pushes back hard enough to stop the press. Past the hold at half the depth,
    // the point is judged by the force held there (the tissue is firm); before it, by
    // nothing: a force that high so soon is the surface still moving from the last press,
    // and the point is left out.
    p.force_n = p.settled && p.half_vertical ? p.half_force_n : -1.0;
    if (verbose_) {
      say("palpate: (%.3f, %.3f) m, contact at z %.4f m: %.3f N at %.1f mm, stopped at %.3f N before %.0f mm%s", p.x, p.y, contact_z_, p.half_force_n,
          1e3 * std::min(contact_z_ - z_, 0.5 * depth_), magnitude(force_), 1000 * depth_,
          !p.settled      ? " (before half way: left out)"
          : p.force_n < 0 ? " (steep: left out)"
                          : "");
    }
    phase_ = Phase::lift;
    return;
  }
  // The marking press goes half as deep: where the tip still holds on to the surface, so
  // that the mark is made touching the tissue.
  const bool mark = marking_ && current_ + 1 == probes_.size();
  const double depth = mark || !p.settled ? 0.5 * depth_ : depth_;
  z_ = std::max(contact_z_ - depth, z_ - kPressSpeed * dt);
  if (z_ <= contact_z_ - depth) start_hold(mark || p.settled ? Phase::dwell : Phase::settle, t);
}

void PalpatingDevice::start_hold(Phase phase, double t) {
  phase_ = phase;
  phase_t_ = t;
  settle_sum_ = {};
  settle_samples_ = 0;
}

void PalpatingDevice::hold(Probe& p, double t) {
  // Held still, at DEPTH / 2 and then at DEPTH; the force is the mean over the end of each
  // hold. The marking press holds briefly, pressing button 1 for its second half.
  const bool mark = marking_ && current_ + 1 == probes_.size();
  const double hold_s = mark ? kDwellS : kSettleS;
  if (mark) buttons_ = t - phase_t_ < 0.5 * kDwellS ? 0u : 1u;
  if (t - phase_t_ >= hold_s - kSettleMeanS) {
    for (int k = 0; k < 3; ++k) settle_sum_[k] += force_[k];
    ++settle_samples_;
  }
  if (t - phase_t_ < hold_s) return;
  protocol::Vector3 mean{};
  for (int k = 0; k < 3; ++k) mean[k] = settle_sum_[k] / std::max(1, settle_samples_);
  const double F = magnitude(mean);
  if (phase_ == Phase::settle) {
    p.half_force_n = F;
    p.half_vertical = F > 0 && mean[2] >= kMinVerticalShare * F;
    p.settled = true;
    phase_ = Phase::press;
    return;
  }
  // Judged by the forces held at half the depth and at the full depth together: half way
  // alone the lump is barely reached, and the full depth alone misleads where the tip slips
  // sideways off a stiff spot and the force stops growing.
  p.force_n = p.half_vertical ? p.half_force_n + F : -1.0;
  if (verbose_ && !mark) {
    say("palpate: (%.3f, %.3f) m, contact at z %.4f m: %.3f N at %.0f mm, %.3f N at %.0f mm%s", p.x, p.y, contact_z_, p.half_force_n, 500 * depth_, F,
        1000 * depth_, p.force_n < 0 ? " (steep: left out)" : "");
  }
  buttons_ = 0;
  phase_ = Phase::lift;
}

void PalpatingDevice::lift(double dt) {
  // Slowly while touching, so that the tissue follows the tip back and is not left ringing
  // for the next press; then fast.
  z_ = std::min(safe_z_, z_ + (z_ < contact_z_ ? kPressSpeed : kLiftSpeed) * dt);
  if (z_ >= safe_z_) next_point();
}

void PalpatingDevice::render(const protocol::Vector3& f, bool in_contact) {
  force_ = f;
  contact_ = in_contact;
}

}  // namespace viscera::haptic
