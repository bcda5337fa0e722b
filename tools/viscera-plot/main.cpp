// viscera-plot: the force a haptic client felt, from its reports (haptic-client --report), several  // SPDX-License-Identifier: Apache-2.0
// in one SVG: the same press on two tissues side by side, against the tip's depth below its first
// contact or against time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/plot/svg_plot.hpp"

namespace {

using viscera::common::InputError;
using viscera::common::JsonObject;
using viscera::common::UsageError;

/// A report's samples as a series: |F| against depth (below the first contact) or time.
viscera::plot::Series read_report(const std::string& path, const std::string& label, bool by_depth, const std::string& colour) {
  const nlohmann::json j = viscera::common::parse_json(viscera::common::read_text_file(path, std::size_t{1} << 30), path);
  const JsonObject top(j, path);
  const nlohmann::json& samples = top.array("samples", 1);
  viscera::plot::Series s{label, {}, {}, colour};
  double contact_z = NAN;
  double peak = 0, peak_at = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const JsonObject o(samples[k], path, "samples[" + std::to_string(k) + "]");
    const double t = o.number("t_s", 0, 1e7);
    const double z = o.number("tip_z_m", -1e3, 1e3);
    const auto f = o.numbers("force_n", 3, -1e6, 1e6);
    const double force = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (std::isnan(contact_z) && o.value().value("in_contact", false)) contact_z = z;
    if (by_depth && std::isnan(contact_z)) continue;
    const double x = by_depth ? 1e3 * (contact_z - z) : t;
    s.x.push_back(x);
    s.y.push_back(force);
    if (force > peak) {
      peak = force;
      peak_at = x;
    }
  }
  if (s.x.empty()) throw InputError(path, 0, "samples", "the tool never touched the organ (no sample in contact)");
  std::printf("%s (%s): %zu samples, peak force %.3g N at %s %.3g %s\n", label.c_str(), path.c_str(), s.x.size(), peak, by_depth ? "depth" : "time",
              peak_at, by_depth ? "mm" : "s");
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl("viscera-plot",
                                  "Plots the force haptic clients felt (their --report files) in one SVG, each REPORT.json[=LABEL]\n"
                                  "a curve: the magnitude of the force [N] against the tip's depth below its first contact [mm]\n"
                                  "(--x depth: loading and unloading, a hysteresis loop for viscous tissue) or against time [s].\n"
                                  "Prints each report's peak force.");
  cl.usage("viscera-plot REPORT.json[=LABEL]... --svg OUT.svg [--replace] [--x depth|time] [--title TEXT]");
  cl.flag("svg", "PATH", "the SVG to write (required; never one of the reports)");
  cl.flag("x", "AXIS", "depth (below the first contact) or time", "depth");
  cl.flag("title", "TEXT", "the plot's title", "The same press on each tissue");
  cl.option_switch("replace", "replace the --svg file if it exists (never through a symbolic link)");
  cl.allow_positional(8);
  try {
    if (!cl.parse(argc, argv)) return 0;
    if (cl.positional().empty()) throw UsageError("no REPORT.json to plot");
    if (!cl.has("svg")) throw UsageError("--svg is required");
    const std::string axis = cl.text("x");
    if (axis != "depth" && axis != "time") throw UsageError("--x: '" + axis + "' is not depth or time");
    const bool by_depth = axis == "depth";
    const std::string svg = cl.text("svg");
    std::vector<std::string> paths;
    for (const std::string& arg : cl.positional()) paths.push_back(arg.substr(0, arg.find('=')));
    viscera::common::refuse_overwrite(svg, paths, "--svg");
    viscera::common::refuse_existing_output(svg, cl.has("replace"), "--svg");
    viscera::plot::Figure fig{cl.text("title"), by_depth ? "depth below the first contact [mm]" : "time [s]", "force on the tool [N]", {}};
    const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf", "#7f7f7f"};
    for (const std::string& arg : cl.positional()) {
      const auto eq = arg.find('=');
      const std::string path = arg.substr(0, eq);
      const std::string label = eq == std::string::npos ? path : arg.substr(eq + 1);
      fig.series.push_back(read_report(path, label, by_depth, colours[fig.series.size() % 8]));
    }
    viscera::plot::write_svg(svg, fig);
    std::printf("wrote %s\n", svg.c_str());
    return 0;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-plot: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-plot: %s\n", e.what());
    return 2;
  }
}
