#pragma once  // SPDX-License-Identifier: Apache-2.0
// A virtual device that plays a scripted gesture relative to the organ (its bounds from the
// scene state) and reacts to contact the way a hand does: it moves down from 1 cm above the
// organ's top centre until the force says "contact", then
//   press: presses DEPTH further by mid-run, comes back to the contact height by the end;
//   grasp: goes DEPTH beyond contact within 5% of the run with the jaws closed, pulls up PULL by
//          75% of the run, then opens the jaws and holds; with a HOLD time it pulls up at 1 cm/s,
//          holds for HOLD seconds, then opens;
//   hold:  presses until the force is FORCE and keeps it there (an integral controller on the
//          force it feels, as a hand holding a steady pressure), until the end of the run;
//   incise: a scalpel (docs/CUTTING.md) starts LENGTH/2 before the top centre along x (OFFSET_Y
//          beside it along y); from
//          contact it holds the cut button, sinks DEPTH into the tissue within 0.2 s, draws the
//          blade LENGTH along +x until 0.3 s before the end, rises back to the contact height and
//          lets the button go 50 ms before the end.
#include <limits>
#include <string>

#include "viscera/client/device.hpp"

namespace viscera::haptic {

class ScriptedDevice : public client::Device {
 public:
  /// hold_s < 0: the grasp's timing by the run's length; force_n: the hold script's target.
  ScriptedDevice(std::string script, const protocol::Scene& scene, double duration_s, double depth_m, double pull_m, double hold_s = -1,
                 double force_n = 1.0, double length_m = 0.04, double offset_y_m = 0.0);
  std::string name() const override { return "scripted " + script_; }
  client::DeviceSample read(double t_s) override;
  void render(const protocol::Vector3& force_n, bool in_contact) override;

 private:
  std::string script_;
  double cx_, cy_, top_, bottom_, duration_, depth_, pull_, hold_, target_force_, length_, search_speed_;
  double t_ = 0, z_ = 0, force_ = 0, hold_z_ = 0, hold_t_ = 0;
  double contact_z_ = std::numeric_limits<double>::quiet_NaN(), contact_t_ = 0;
};

}  // namespace viscera::haptic
