#include "viscera/plot/svg_plot.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "viscera/common/file_bytes.hpp"

namespace viscera::plot {

namespace {
// "Nice" tick step for a range: 1, 2 or 5 times a power of ten, about 6 ticks.
double tick_step(double span) {
  const double raw = span / 6.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}
std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", std::abs(v) < 1e-15 ? 0.0 : v);
  return b;
}
std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return o;
}
}  // namespace

void write_svg(const std::string& path, const Figure& input) {
  Figure f = input;
  if (f.log_x)
    for (auto& s : f.series) {
      Series kept = s;
      kept.x.clear();
      kept.y.clear();
      for (std::size_t k = 0; k < s.x.size(); ++k)
        if (s.x[k] > 0) {
          kept.x.push_back(std::log10(s.x[k]));
          kept.y.push_back(s.y[k]);
        }
      s = kept;
    }
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& s : f.series)
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) continue;
      x0 = std::min(x0, s.x[k]);
      x1 = std::max(x1, s.x[k]);
      y0 = std::min(y0, s.y[k]);
      y1 = std::max(y1, s.y[k]);
    }
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  const double ypad = 0.05 * (y1 - y0);
  y0 -= ypad;
  y1 += ypad;
  const double L = 90, R = 20, T = 40, B = 60;
  const double W = f.width_px - L - R, H = f.height_px - T - B;
  const auto px = [&](double x) { return L + (x - x0) / (x1 - x0) * W; };
  const auto py = [&](double y) { return T + (y1 - y) / (y1 - y0) * H; };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << f.width_px << "\" height=\"" << f.height_px
    << "\" font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << f.width_px / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape(f.title) << "</text>\n";
  const double xs = f.log_x ? 1.0 : tick_step(x1 - x0), ys = tick_step(y1 - y0);
  for (double x = std::ceil(x0 / xs) * xs; x <= x1 + 1e-9 * xs; x += xs)
    o << "<line x1=\"" << px(x) << "\" y1=\"" << T << "\" x2=\"" << px(x) << "\" y2=\"" << T + H << "\" stroke=\"#e5e5e5\"/><text x=\"" << px(x)
      << "\" y=\"" << T + H + 18 << "\" text-anchor=\"middle\">" << fmt(f.log_x ? std::pow(10.0, x) : x) << "</text>\n";
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9 * ys; y += ys)
    o << "<line x1=\"" << L << "\" y1=\"" << py(y) << "\" x2=\"" << L + W << "\" y2=\"" << py(y) << "\" stroke=\"#e5e5e5\"/><text x=\"" << L - 6
      << "\" y=\"" << py(y) + 4 << "\" text-anchor=\"end\">" << fmt(y) << "</text>\n";
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << W << "\" height=\"" << H << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << L + W / 2 << "\" y=\"" << f.height_px - 15 << "\" text-anchor=\"middle\">" << escape(f.x_label) << "</text>\n";
  o << "<text transform=\"translate(18," << T + H / 2 << ") rotate(-90)\" text-anchor=\"middle\">" << escape(f.y_label) << "</text>\n";
  for (const auto& s : f.series) {
    o << "<polyline fill=\"none\" stroke=\"" << s.colour << "\" stroke-width=\"" << s.width << "\"";
    if (!s.dash.empty()) o << " stroke-dasharray=\"" << s.dash << "\"";
    o << " points=\"";
    for (std::size_t k = 0; k < s.x.size(); ++k)
      if (std::isfinite(s.x[k]) && std::isfinite(s.y[k])) o << px(s.x[k]) << "," << py(s.y[k]) << " ";
    o << "\"/>\n";
  }
  double ly = T + 14;
  for (const auto& s : f.series) {
    o << "<line x1=\"" << L + W - 250 << "\" y1=\"" << ly - 4 << "\" x2=\"" << L + W - 220 << "\" y2=\"" << ly - 4 << "\" stroke=\"" << s.colour
      << "\" stroke-width=\"2\"" << (s.dash.empty() ? "" : " stroke-dasharray=\"" + s.dash + "\"") << "/><text x=\"" << L + W - 214 << "\" y=\"" << ly
      << "\">" << escape(s.label) << "</text>\n";
    ly += 18;
  }
  o << "</svg>\n";
  common::write_file_text(path, o.str());
}

}  // namespace viscera::plot
