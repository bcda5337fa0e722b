#pragma once  // SPDX-License-Identifier: Apache-2.0
// A virtual device that palpates the organ from above to find what is stiffer inside it, as a
// trainee's hand would: at each point of a grid over the organ's top (2 cm apart, then 1 cm apart
// around the stiffest), it comes down until it touches, presses DEPTH / 2 further and holds still
// there until the tissue settles, notes the force it feels then (the mean over the last 50 ms of
// 0.2 s held: a force read while still moving measures how fast the tissue gets out of the way,
// not how stiff it is), presses on to DEPTH and lifts off; then it
// presses at the centre of the stiff area around the stiffest point and marks it (button 1). It
// never reads the scene's regions: only the forces tell it where the nodule is. Where the surface
// slopes steeply (the force it feels half way leans more than about 37 degrees from the vertical),
// the point is left out: a hand presses along the surface's normal, and a vertical press into a
// slope measures the slope, not the tissue. A press stops at a safe 2 N; the point is then judged
// by the force half way, or by the 2 N that stopped it before half way (a hard lump).
#include <string>
#include <utility>
#include <vector>

#include "viscera/client/device.hpp"

namespace viscera::haptic {

class PalpatingDevice : public client::Device {
 public:
  /// verbose: a line per point pressed (its place and the forces felt).
  PalpatingDevice(const protocol::Scene& scene, double depth_m, bool verbose);
  std::string name() const override { return "scripted palpate"; }
  client::DeviceSample read(double t_s) override;
  void render(const protocol::Vector3& force_n, bool in_contact) override;
  /// While the server's newest answer is over 5 ms old, the search holds still where it touches
  /// the tissue (and a hold's clock stops): it never presses on blind.
  void model_age(double age_s) override { model_age_s_ = age_s; }

 private:
  enum class Phase { travel, descend, press, settle, dwell, lift, done };
  struct Probe {
    double x = 0, y = 0;
    double force_n = -1;  ///< what the point is judged by: the force at DEPTH / 2; -1: not yet, no tissue, or steep
    double half_force_n = 0;  ///< felt at DEPTH / 2, held still
    bool half_vertical = false;  ///< ... and mostly vertical there
    bool settled = false;  ///< the hold at DEPTH / 2 is done
  };
  // One period of each phase; `p` the point being probed, `t` the device's time [s], `dt` since
  // the last period [s].
  void travel(Probe& p, double dt);  ///< above the tissue to the next point (straight up first)
  void descend(double dt);  ///< down until contact (or past the bottom: no tissue here)
  void press(Probe& p, double t, double dt);  ///< into the tissue to half the depth, then the full depth
  void start_hold(Phase phase, double t);
  void hold(Probe& p, double t);  ///< held still at a depth (settle, dwell), the force averaged at its end
  void lift(double dt);  ///< up, slowly while touching
  void next_point();
  /// The centre of the stiff area around `best`: the points within 1.5 cm of it, each weighted by
  /// how much more force it felt than the median point (a hand marks the middle of the lump it
  /// felt, not the one spot it pressed hardest).
  std::pair<double, double> stiff_centre(const Probe& best) const;
  void add_neighbours(double x, double y, double spacing);

  std::vector<Probe> probes_;
  std::size_t current_ = 0;
  bool refined_ = false, marking_ = false;
  Phase phase_ = Phase::travel;
  double safe_z_, bottom_, depth_;
  double x_, y_, z_, t_ = 0, phase_t_ = 0, contact_z_ = 0;
  protocol::Vector3 force_{};
  protocol::Vector3 settle_sum_{};  // force summed over the end of the hold at DEPTH / 2 [N]
  int settle_samples_ = 0;
  double model_age_s_ = 0;
  bool contact_ = false, verbose_ = false;
  std::uint32_t buttons_ = 0;
};

}  // namespace viscera::haptic
