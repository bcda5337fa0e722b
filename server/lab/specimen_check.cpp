#include "viscera/lab/specimen_check.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "viscera/lab/fit.hpp"
#include "viscera/lab/format_figures.hpp"
#include "viscera/lab/specimen_simulation.hpp"
#include "viscera/lab/test_history.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

namespace viscera::lab {

SpecimenCheck check_on_specimen(const MaterialModel& m, const Dataset& d, const std::function<void(const std::string&)>& say) {
  SpecimenCheck c;
  c.model = m.describe();
  std::string why;
  if (!specimen_supports(m, d.mode, &why)) {
    c.note = why;
    return c;
  }
  c.note = why;
  std::string departure;
  try {
    const ShapeCalibration calibration = calibrate_elastic_shape(m, d);
    if (m.has(Mechanism::strain_stiffening) || m.has(Mechanism::tension_compression_asymmetry)) {
      char text[500];
      std::snprintf(text, sizeof text,
                    ": on the specimen B = %.3g, r = %.3g for the law's B = %.3g, r = %.3g (the specimen's elastic curve over strains "
                    "%.3g to %.3g against the law's: %.1f%% RMS with the law's constants, %.1f%% calibrated)",
                    calibration.gps_b, calibration.gps_r, calibration.law_b, calibration.law_r, calibration.strain_lo, calibration.strain_hi,
                    100 * calibration.uncalibrated_mismatch, 100 * calibration.mismatch);
      c.note += text;
    }
    for (std::size_t k = 0; k < d.tests.size(); ++k) {
      const TestData& t = d.tests[k];
      say("  " + c.model + " on the specimen: " + t.file + " (" + std::to_string(k + 1) + " of " + std::to_string(d.tests.size()) +
          format_figures(", %.4g s of history; at most %.0f s)", t.time_s.back() - t.time_s.front(), kSpecimenSecondsPerTest));
      const SpecimenResult r = simulate_specimen(m, d, t, &calibration, kSpecimenSecondsPerTest);
      if (t.control == Control::strain && departure.empty()) {
        // Where the specimen first leaves the law by more than a tenth of the test's largest stress
        // (both from an untouched specimen).
        const std::vector<double> law = predict_stress(m, untouched(t));
        double peak = 0.0;
        for (const double s : law) peak = std::max(peak, std::abs(s));
        for (std::size_t i = 0; i < r.stress_pa.size() && i < law.size(); ++i)
          if (std::abs(r.stress_pa[i] - law[i]) > 0.1 * peak) {
            departure = format_figures("; the specimen first leaves the law by more than a tenth of the largest stress at strain %.3g", t.strain[i]) +
                        " in " + t.file + format_figures(" (%.4g Pa against %.4g Pa)", r.stress_pa[i], law[i]);
            break;
          }
      }
      c.files.push_back(t.file);
      c.specimen_rms_pa.push_back(r.rms_pa);
      c.law_rms_pa.push_back(rms_error_pa(m, t));
      c.steps += r.steps;
      c.newton_iterations += r.newton_iterations;
    }
    c.ran = true;
    c.note += c.note.empty() && !departure.empty() ? departure.substr(2) : departure;
    if (m.has(Mechanism::first_load_softening) && m.history_carried)
      c.note += std::string(c.note.empty() ? "" : "; ") +
                "the specimen runs each test from an untouched state, the law with what the tests before it left (first-load softening "
                "carried between tests): their errors differ by that history";
  } catch (const tissue::SimulationError& e) {
    c.note = "the specimen simulation failed on " + (c.files.size() < d.tests.size() ? d.tests[c.files.size()].file : std::string("a test")) + ": " +
             e.what() + "; only the material-point law is reported";
    c.files.clear();
    c.specimen_rms_pa.clear();
    c.law_rms_pa.clear();
  }
  return c;
}

}  // namespace viscera::lab
