#pragma once  // SPDX-License-Identifier: Apache-2.0
// A layer of thickness H in simple shear (the paper's Figure 2): base fixed, top loaded by a
// uniform shear traction tau(t), shear waves travelling between the faces. Two solutions:
//  - exact, for any linear viscoelastic material given by its modulus M(s) in the Laplace variable
//    s: top displacement u(H, s) = tau(s) tanh(k H) / (M k), k = s sqrt(rho / M), inverted with
//    the FFT along a line Re s = alpha > 0 (exponential window against wrap-around);
//  - simulated: linear finite elements in z with lumped masses, explicit symplectic Euler at the
//    computed stable step, and memory variables updated exactly (MemoryStep).
#include <complex>
#include <functional>
#include <vector>

#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"

namespace viscera::tissue {

struct ShearLayer {
  double thickness_m = 0.1;
  double density_kg_m3 = 1e3;
};

/// Top displacement [m] at t = k dt, k = 0..samples-1, exact for the modulus M(s) [Pa].
std::vector<double> exact_top_displacement(const ShearLayer& layer, const std::function<std::complex<double>(std::complex<double>)>& modulus,
                                           const std::function<double(double)>& traction_pa, double dt_s, std::size_t samples);

struct ColumnResult {
  std::vector<double> top_displacement_m;  ///< at the output times
  double dt_s = 0.0;  ///< integration step used
  long steps = 0;
};

/// Memory-variable simulation of the same layer with `elements` linear elements.
ColumnResult simulate_memory_column(const ShearLayer& layer, const StandardLinearSolids& solids, const std::function<double(double)>& traction_pa,
                                    double output_dt_s, std::size_t samples, int elements);

}  // namespace viscera::tissue
