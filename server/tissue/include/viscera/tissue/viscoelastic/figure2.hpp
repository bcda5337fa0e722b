#pragma once  // SPDX-License-Identifier: Apache-2.0
// The paper's Figure 2 (docs/MODEL.md section 3): a block 10 cm thick (rho = 1e3 kg/m^3,
// |G| = 1e3 Pa at 2 Hz, Q = 4.8), base fixed, top sheared by a constant traction for 1 s, then
// released. Top displacement per pascal of traction, 0-4 s, from:
//  1. the exact constant-Q response (frequency domain with Kjartansson's modulus, inverse FFT);
//  2. viscera's memory variables: a 1D column of linear elements and the 3D GPS on a tetrahedral
//     block (laterally constrained to simple shear), both explicit at the computed stable step;
//  3. a Kelvin-Voigt solid with one relaxation time matched at 2 Hz (exact, frequency domain).
#include <functional>
#include <memory>
#include <vector>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/viscoelastic/constant_q_fit.hpp"

namespace viscera::tissue {

struct Figure2Options {
  double thickness_m = 0.1, density_kg_m3 = 1e3, modulus_pa = 1e3, reference_frequency_hz = 2.0, q = 4.8;
  double band_low_hz = 0.01, band_high_hz = 10.0;
  int mechanisms = 3;
  double load_duration_s = 1.0, end_time_s = 4.0, sample_rate_hz = 250.0;
  int column_elements = 100;  ///< 1D column
  int block_layers = 20;  ///< 3D block: cells through the thickness (6 tets each)
};

struct Figure2 {
  std::vector<double> time_s, exact_cq_m, memory_variables_m, gps_block_m, kelvin_voigt_m;
  ConstantQFit fit;
  double peak_m = 0.0;
  /// RMS difference from the exact CQ response over 0-end, relative to its peak.
  double rms_memory_variables = 0.0, rms_gps_block = 0.0, rms_kelvin_voigt = 0.0;
  double column_dt_s = 0.0, block_dt_s = 0.0;
};

Figure2 compute_figure2(const Figure2Options& options = {});

/// The 3D block of Figure 2 ready to integrate: one column of cells, every node restricted to
/// motion along x, base fixed, the top loaded by 1 Pa times `traction(t)` (consistent nodal forces
/// of the top triangles); the GPS with the memory variables of `options`.
struct ShearBlock {
  std::shared_ptr<TetMesh> mesh;
  std::unique_ptr<GpsModel> model;
  BoundaryConditions bc;
  std::vector<std::int32_t> top;  ///< nodes whose mean x displacement is the output
  std::vector<double> density;
};
ShearBlock make_shear_block(const Figure2Options& options, const std::function<double(double)>& traction);

}  // namespace viscera::tissue
