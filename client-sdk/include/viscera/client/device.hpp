#pragma once  // SPDX-License-Identifier: Apache-2.0
// The interface between a haptic client and a device. A client samples the device at its rate,
// sends the pose to the server, and commands the device with the force rendered from the
// server's local model. A real device (a Phantom/Touch through OpenHaptics, a Falcon through
// libnifalcon, a device driven by CHAI3D, ...) implements this class and hands it to run_device
// (device_runner.hpp), which runs the whole loop; the virtual devices of tools/haptic-client
// (scripted, palpating, trajectory file) do the same.
#include <cstdint>
#include <string>

#include "viscera/protocol/messages.hpp"

namespace viscera::client {

/// One reading of a device, in the scene frame.
struct DeviceSample {
  protocol::Vector3 tip_m{};  ///< tool tip position [m]
  double jaw_rad = 0.5;  ///< jaw opening [rad] (graspers; 0 = closed)
  std::uint32_t buttons = 0;
  bool finished = false;  ///< a virtual device that ran out of trajectory
};

class Device {
 public:
  virtual ~Device() = default;
  virtual std::string name() const = 0;
  /// Reads the device at t_s seconds after the start of the run.
  virtual DeviceSample read(double t_s) = 0;
  /// Commands the force the user should feel [N], already limited to the device's maximum, and
  /// whether the tool touches tissue.
  virtual void render(const protocol::Vector3& force_n, bool in_contact) = 0;
  /// How old the newest answer from the server is [s], each period after render(): about one
  /// period while the server keeps up, more while it is late. A hand cannot be held back; a
  /// scripted or robotic device may hold still until answers come again (the palpating device
  /// does: pressed on blind through a 60 ms stall of the server, it reached 26.6 N).
  virtual void model_age(double /*age_s*/) {}
};

}  // namespace viscera::client
