#include "trajectory_device.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/number_text.hpp"

namespace viscera::haptic {

namespace {
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string c;
  while (std::getline(ss, c, ',')) {
    const auto a = c.find_first_not_of(" \t\r"), b = c.find_last_not_of(" \t\r");
    cells.push_back(a == std::string::npos ? "" : c.substr(a, b - a + 1));
  }
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}
}  // namespace

std::vector<TrajectoryPoint> read_trajectory(const std::string& path) {
  // A regular file of bounded size, read whole: a FIFO blocked the reader for ever, /dev/zero grew
  // it to 735 MB in 5 s. 256 MiB holds an hour at 1 kHz of 70-byte lines.
  const std::vector<std::uint8_t> bytes = common::read_file_bytes(path, std::uint64_t{256} << 20);
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  const auto fail = [&](int line, const std::string& column, const std::string& what) {
    throw std::runtime_error(path + ":" + std::to_string(line) + ": " + (column.empty() ? "" : "column " + column + ": ") + what);
  };
  std::string line;
  int number = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    header = split(line);
  }
  if (header.empty()) fail(number, "", "no header row (expected time_s,x_m,y_m,z_m[,jaw_rad][,buttons])");
  const std::vector<std::string> known = {"time_s", "x_m", "y_m", "z_m", "jaw_rad", "buttons"};
  std::vector<int> column_of(known.size(), -1);
  for (std::size_t c = 0; c < header.size(); ++c) {
    std::size_t k = 0;
    while (k < known.size() && known[k] != header[c]) ++k;
    if (k == known.size()) fail(number, header[c], "unknown column (known: time_s, x_m, y_m, z_m, jaw_rad, buttons)");
    if (column_of[k] >= 0) fail(number, header[c], "appears twice");
    column_of[k] = static_cast<int>(c);
  }
  for (std::size_t k = 0; k < 4; ++k)
    if (column_of[k] < 0) fail(number, known[k], "missing from the header");
  std::vector<TrajectoryPoint> points;
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    const auto cells = split(line);
    if (cells.size() != header.size()) fail(number, "", std::to_string(cells.size()) + " values for " + std::to_string(header.size()) + " columns");
    double v[6] = {0, 0, 0, 0, 0.5, 0};
    for (std::size_t k = 0; k < known.size(); ++k) {
      if (column_of[k] < 0) continue;
      const std::string& text = cells[static_cast<std::size_t>(column_of[k])];
      std::string why;
      const auto x = viscera::common::read_number(text, &why);
      if (!x) fail(number, known[k], why);
      v[k] = *x;
    }
    if (v[0] < 0 || (!points.empty() && v[0] <= points.back().t_s))
      fail(number, "time_s", std::to_string(v[0]) + " s is not after the previous row's time (times start at 0 and increase)");
    for (int k = 1; k <= 3; ++k)
      if (std::abs(v[k]) > 10) fail(number, known[static_cast<std::size_t>(k)], std::to_string(v[k]) + " m is beyond 10 m: are the units metres?");
    if (v[4] < 0 || v[4] > M_PI) fail(number, "jaw_rad", std::to_string(v[4]) + " is outside [0, pi] rad");
    if (v[5] < 0 || v[5] > 4294967295.0 || v[5] != std::floor(v[5])) fail(number, "buttons", std::to_string(v[5]) + " is not a 32-bit mask");
    points.push_back({v[0], {v[1], v[2], v[3]}, v[4], static_cast<std::uint32_t>(v[5])});
  }
  if (points.empty()) fail(number, "", "no trajectory rows after the header");
  return points;
}

TrajectoryDevice::TrajectoryDevice(std::string path, std::vector<TrajectoryPoint> points, const protocol::Vector3& origin)
    : path_(std::move(path)), points_(std::move(points)) {
  for (auto& p : points_)
    for (int d = 0; d < 3; ++d) p.tip_m[static_cast<std::size_t>(d)] += origin[static_cast<std::size_t>(d)];
}

client::DeviceSample TrajectoryDevice::read(double t) {
  while (segment_ + 1 < points_.size() && points_[segment_ + 1].t_s <= t) ++segment_;
  const TrajectoryPoint& a = points_[segment_];
  if (segment_ + 1 == points_.size() || t <= a.t_s) return {a.tip_m, a.jaw_rad, a.buttons, t >= points_.back().t_s};
  const TrajectoryPoint& b = points_[segment_ + 1];
  const double s = (t - a.t_s) / (b.t_s - a.t_s);
  protocol::Vector3 tip;
  for (std::size_t d = 0; d < 3; ++d) tip[d] = a.tip_m[d] + s * (b.tip_m[d] - a.tip_m[d]);
  return {tip, a.jaw_rad + s * (b.jaw_rad - a.jaw_rad), a.buttons, false};
}

}  // namespace viscera::haptic
