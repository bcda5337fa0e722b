#pragma once  // SPDX-License-Identifier: Apache-2.0
// A virtual device that plays a trajectory file (docs/PROTOCOL.md): CSV with a header row,
// columns time_s, x_m, y_m, z_m and optionally jaw_rad and buttons; times strictly increasing
// from 0. Positions are in the scene frame, or relative to the organ's top centre (the centre of
// its bounds in x and y, the top of its bounds in z) with frame "organ-top". Between rows the
// tip moves linearly; after the last row the device reports finished. Bad files get one error
// naming the file, line, column and value.
#include <string>
#include <vector>

#include "viscera/client/device.hpp"

namespace viscera::haptic {

struct TrajectoryPoint {
  double t_s = 0;
  protocol::Vector3 tip_m{};
  double jaw_rad = 0.5;
  std::uint32_t buttons = 0;
};

/// Reads and checks a trajectory file; throws std::runtime_error naming file, line and column.
std::vector<TrajectoryPoint> read_trajectory(const std::string& path);

class TrajectoryDevice : public client::Device {
 public:
  /// origin: added to every position (the organ's top centre for frame "organ-top", else 0).
  TrajectoryDevice(std::string path, std::vector<TrajectoryPoint> points, const protocol::Vector3& origin);
  std::string name() const override { return "trajectory " + path_; }
  client::DeviceSample read(double t_s) override;
  void render(const protocol::Vector3&, bool) override {}

 private:
  std::string path_;
  std::vector<TrajectoryPoint> points_;
  std::size_t segment_ = 0;
};

}  // namespace viscera::haptic
