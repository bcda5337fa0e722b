#pragma once  // SPDX-License-Identifier: Apache-2.0
// Minimal line plots as SVG (no dependency): axes with ticks, labelled series, a legend.
#include <string>
#include <vector>

namespace viscera::plot {

struct Series {
  std::string label;
  std::vector<double> x, y;
  std::string colour = "#1f77b4";
  std::string dash;  ///< SVG stroke-dasharray, empty = solid
  double width = 1.6;
};

struct Figure {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  int width_px = 900, height_px = 520;
  bool log_x = false;  ///< logarithmic x axis (points with x <= 0 are dropped)
};

/// Writes the figure; throws std::runtime_error naming the path if it cannot be written.
void write_svg(const std::string& path, const Figure& figure);

}  // namespace viscera::plot
