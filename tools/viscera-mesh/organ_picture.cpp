#include "organ_picture.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "label_fidelity.hpp"

namespace viscera::meshing {

std::string organ_picture_svg(const LabelledMesh& mesh, const std::vector<PictureLabel>& labels, const std::vector<char>& held,
                              const std::string& title) {
  std::vector<std::int32_t> all;
  all.reserve(labels.size());
  for (const PictureLabel& l : labels) all.push_back(l.label);
  std::vector<std::int32_t> owner;
  const auto faces = label_boundary(mesh, all, &owner);
  // A view from the front, 35 degrees above: screen x along the scene's x, screen y up.
  const double tilt = 35 * M_PI / 180;
  const Eigen::Vector3d right(1, 0, 0), up(0, std::sin(tilt), std::cos(tilt)), toward(0, -std::cos(tilt), std::sin(tilt));
  const Eigen::Vector3d light = (toward + 0.6 * up - 0.4 * right).normalized();
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const auto& p : mesh.nodes) {
    const Eigen::Vector2d s(p.dot(right), p.dot(up));
    lo = lo.cwiseMin(s), hi = hi.cwiseMax(s);
  }
  const double width = 720, height = 520, margin = 40;
  const double scale = std::min((width - 2 * margin) / (hi.x() - lo.x()), (height - 2 * margin - 30) / (hi.y() - lo.y()));
  const auto screen = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(margin + (p.dot(right) - lo.x()) * scale, height - margin - (p.dot(up) - lo.y()) * scale);
  };
  struct Drawn {
    double depth;
    std::size_t face;
  };
  std::vector<Drawn> order;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto& t = faces[f];
    const Eigen::Vector3d n = (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]);
    if (n.dot(toward) <= 0) continue;  // faces away
    order.push_back({(mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]]).dot(toward), f});
  }
  std::sort(order.begin(), order.end(), [](const Drawn& a, const Drawn& b) { return a.depth < b.depth || (a.depth == b.depth && a.face < b.face); });
  static const double kColours[][3] = {{0.62, 0.22, 0.18}, {0.30, 0.62, 0.25}, {0.85, 0.70, 0.25}, {0.30, 0.45, 0.75}, {0.60, 0.40, 0.70}};
  char buf[512];
  std::string s;
  std::snprintf(buf, sizeof buf,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\">\n"
                "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                width, height, width, height);
  s += buf;
  for (const Drawn& d : order) {
    const auto& t = faces[d.face];
    const std::size_t e = static_cast<std::size_t>(owner[d.face]);
    std::size_t colour = 0;
    for (std::size_t k = 0; k < labels.size(); ++k)
      if (labels[k].label == mesh.label[e]) colour = k % 5;
    const Eigen::Vector3d n = (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]).normalized();
    double shade = 0.35 + 0.65 * std::max(0.0, n.dot(light));
    if (!held.empty() && held[e]) shade *= 0.45;
    const Eigen::Vector2d a = screen(mesh.nodes[t[0]]), b = screen(mesh.nodes[t[1]]), c = screen(mesh.nodes[t[2]]);
    const int r = static_cast<int>(255 * kColours[colour][0] * shade), g = static_cast<int>(255 * kColours[colour][1] * shade),
              bl = static_cast<int>(255 * kColours[colour][2] * shade);
    std::snprintf(buf, sizeof buf,
                  "<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f\" fill=\"rgb(%d,%d,%d)\" stroke=\"rgb(%d,%d,%d)\" stroke-width=\"0.3\"/>\n", a.x(),
                  a.y(), b.x(), b.y(), c.x(), c.y(), r, g, bl, r, g, bl);
    s += buf;
  }
  // Title, legend, and a 5 cm scale bar.
  std::snprintf(buf, sizeof buf, "<text x=\"%.0f\" y=\"24\" font-family=\"sans-serif\" font-size=\"15\">", margin);
  s += buf;
  for (const char ch : title) s += ch == '<' ? std::string("&lt;") : ch == '&' ? std::string("&amp;") : std::string(1, ch);
  s += "</text>\n";
  double x = margin;
  for (std::size_t k = 0; k < labels.size(); ++k) {
    const auto* c = kColours[k % 5];
    std::snprintf(buf, sizeof buf,
                  "<rect x=\"%.0f\" y=\"%.0f\" width=\"12\" height=\"12\" fill=\"rgb(%d,%d,%d)\"/><text x=\"%.0f\" y=\"%.0f\" "
                  "font-family=\"sans-serif\" font-size=\"12\">%s (label %d)</text>\n",
                  x, height - 22, static_cast<int>(255 * c[0]), static_cast<int>(255 * c[1]), static_cast<int>(255 * c[2]), x + 16, height - 12,
                  labels[k].name.c_str(), labels[k].label);
    s += buf;
    x += 40 + 8.0 * static_cast<double>(labels[k].name.size()) + 60;
  }
  std::snprintf(buf, sizeof buf,
                "<text x=\"%.0f\" y=\"%.0f\" font-family=\"sans-serif\" font-size=\"12\">held faces darker</text>\n"
                "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"black\" stroke-width=\"2\"/>"
                "<text x=\"%.0f\" y=\"%.0f\" font-family=\"sans-serif\" font-size=\"12\">5 cm</text>\n</svg>\n",
                x, height - 12, width - margin - 0.05 * scale, height - 34.0, width - margin, height - 34.0, width - margin - 0.05 * scale,
                height - 40.0);
  s += buf;
  return s;
}

}  // namespace viscera::meshing
