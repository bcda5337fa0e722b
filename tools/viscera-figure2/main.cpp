// viscera-figure2: regenerates the paper's Figure 2 (docs/figure2.csv, docs/figure2.svg).  // SPDX-License-Identifier: Apache-2.0
#include <cstdio>
#include <fstream>
#include <sstream>

#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/plot/svg_plot.hpp"
#include "viscera/tissue/viscoelastic/figure2.hpp"

using namespace viscera::tissue;
using namespace viscera::common;

int main(int argc, char** argv) {
  try {
    viscera::common::CommandLine cl("viscera-figure2",
                                    "Reproduces Figure 2 of Gross & Buess (2001): a 10 cm block (rho 1e3 kg/m^3, |G| = 1e3 Pa at 2 Hz,\n"
                                    "Q = 4.8) sheared by 1 Pa for 1 s, then released. Writes the top displacement [m] of the exact\n"
                                    "constant-Q solution, the memory-variable simulations (1D column and 3D GPS block) and a\n"
                                    "Kelvin-Voigt solid, as CSV and SVG, and prints the RMS errors relative to the exact peak.");
    cl.flag("csv", "PATH", "CSV output", "docs/figure2.csv");
    cl.flag("svg", "PATH", "SVG plot output", "docs/figure2.svg");
    cl.flag("mechanisms", "L", "number of memory variables (standard linear solids), 1-8", "3");
    cl.flag("sample-rate", "HZ", "output samples per second", "250");
    cl.option_switch("replace", "replace the CSV and the SVG if they exist (as when regenerating docs/figure2.*)");
    if (!cl.parse(argc, argv)) return 0;
    refuse_existing_output(cl.text("csv"), cl.has("replace"), "--csv");
    refuse_existing_output(cl.text("svg"), cl.has("replace"), "--svg");
    Figure2Options o;
    o.mechanisms = static_cast<int>(cl.integer("mechanisms"));
    o.sample_rate_hz = cl.number_in("sample-rate", 100, 10000);
    const Figure2 r = compute_figure2(o);
    std::printf("%s", describe(r.fit, {o.q, o.band_low_hz, o.band_high_hz, o.mechanisms, o.modulus_pa, o.reference_frequency_hz}).c_str());
    std::printf("peak top displacement (exact CQ) %.4g m per Pa\n", r.peak_m);
    std::printf("RMS error / peak over 0-%g s: memory variables 1D column %.2f%% (dt %.3g s), 3D GPS block %.2f%% (dt %.3g s), Kelvin-Voigt %.2f%%\n",
                o.end_time_s, 100 * r.rms_memory_variables, r.column_dt_s, 100 * r.rms_gps_block, r.block_dt_s, 100 * r.rms_kelvin_voigt);
    const std::string csv = cl.text("csv");
    std::ostringstream out;
    out << "time_s,exact_cq_m,memory_variables_m,kelvin_voigt_m,gps_block_m\n";
    out.precision(9);
    for (std::size_t k = 0; k < r.time_s.size(); ++k)
      out << r.time_s[k] << ',' << r.exact_cq_m[k] << ',' << r.memory_variables_m[k] << ',' << r.kelvin_voigt_m[k] << ',' << r.gps_block_m[k] << '\n';
    viscera::common::write_file_text(csv, out.str());
    const auto mm = [](const std::vector<double>& v) {
      std::vector<double> o2;
      o2.reserve(v.size());
      for (double x : v) o2.push_back(1e3 * x);
      return o2;
    };
    char title[200];
    std::snprintf(title, sizeof title, "Figure 2: 1 Pa shear for 1 s (RMS/peak: memory variables %.1f%%, GPS 3D %.1f%%, Kelvin-Voigt %.1f%%)",
                  100 * r.rms_memory_variables, 100 * r.rms_gps_block, 100 * r.rms_kelvin_voigt);
    viscera::plot::write_svg(
        cl.text("svg"), {title,
                         "time [s]",
                         "top displacement [mm]",
                         {{"exact constant Q", r.time_s, mm(r.exact_cq_m), "#000000", "", 2.2},
                          {std::to_string(o.mechanisms) + " memory variables (1D column)", r.time_s, mm(r.memory_variables_m), "#d62728", "6 4", 1.6},
                          {std::to_string(o.mechanisms) + " memory variables (3D GPS block)", r.time_s, mm(r.gps_block_m), "#2ca02c", "2 3", 1.6},
                          {"Kelvin-Voigt (one relaxation time)", r.time_s, mm(r.kelvin_voigt_m), "#1f77b4", "10 5", 1.6}}});
    std::printf("wrote %s and %s\n", csv.c_str(), cl.text("svg").c_str());
    return 0;
  } catch (const viscera::common::UsageError& e) {
    std::fprintf(stderr, "viscera-figure2: %s\n", e.what());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "viscera-figure2: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viscera-figure2: %s\n", e.what());
    return 1;
  }
}
