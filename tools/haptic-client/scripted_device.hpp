#pragma once
// A virtual device that plays a scripted gesture relative to the organ (its bounds from the
// scene state) and reacts to contact the way a hand does: it moves down from 1 cm above the
// organ's top centre until the force says "contact", then
//   press: presses DEPTH further by mid-run, comes back to the contact height by the end;
//   grasp: goes DEPTH beyond contact within 5% of the run with the jaws closed, pulls up PULL by
//          75% of the run, then opens the jaws and holds.
#include <limits>
#include <string>

#include "viscera/client/device.hpp"

namespace viscera::haptic {

class ScriptedDevice : public client::Device {
 public:
  ScriptedDevice(std::string script, const protocol::Scene& scene, double duration_s, double depth_m, double pull_m);
  std::string name() const override { return "scripted " + script_; }
  client::DeviceSample read(double t_s) override;
  void render(const protocol::Vector3& force_n, bool in_contact) override;

 private:
  std::string script_;
  double cx_, cy_, top_, bottom_, duration_, depth_, pull_, search_speed_;
  double t_ = 0, z_ = 0;
  double contact_z_ = std::numeric_limits<double>::quiet_NaN(), contact_t_ = 0;
};

}  // namespace viscera::haptic
