#include "viscera/tissue/viscoelastic/shear_layer.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>

#include <unsupported/Eigen/FFT>

namespace viscera::tissue {

std::vector<double> exact_top_displacement(const ShearLayer& layer, const std::function<std::complex<double>(std::complex<double>)>& modulus,
                                           const std::function<double(double)>& traction, double dt, std::size_t samples) {
  // Period long against the output window, fine sampling; exponential window exp(-alpha t).
  std::size_t n = 1;
  const double window = std::max(32.0, 8.0 * dt * static_cast<double>(samples));
  while (static_cast<double>(n) * dt < window) n *= 2;
  const double T = static_cast<double>(n) * dt;
  const double alpha = std::log(1e4) / T;
  std::vector<std::complex<double>> f(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    f[k] = traction(t) * std::exp(-alpha * t);
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> F;
  fft.fwd(F, f);
  const double rho = layer.density_kg_m3, H = layer.thickness_m;
  for (std::size_t k = 0; k < n; ++k) {
    const double kk = k <= n / 2 ? static_cast<double>(k) : static_cast<double>(k) - static_cast<double>(n);
    const double omega = 2 * M_PI * kk / T;
    const std::complex<double> s(alpha, omega);
    const std::complex<double> M = modulus(s);
    const std::complex<double> kappa = s * std::sqrt(rho / M);
    F[k] *= std::tanh(kappa * H) / (M * kappa);
  }
  std::vector<std::complex<double>> u;
  fft.inv(u, F);
  std::vector<double> out(samples);
  for (std::size_t k = 0; k < samples; ++k) out[k] = u[k].real() * std::exp(alpha * static_cast<double>(k) * dt);
  return out;
}

ColumnResult simulate_memory_column(const ShearLayer& layer, const StandardLinearSolids& solids, const std::function<double(double)>& traction,
                                    double output_dt, std::size_t samples, int elements) {
  const std::size_t ne = static_cast<std::size_t>(elements), L = solids.size();
  const double h = layer.thickness_m / elements, rho = layer.density_kg_m3, MU = solids.unrelaxed_modulus_pa;
  // Stable step of a 2-node element with lumped mass: dt <= h / c_U (c_U from the unrelaxed
  // modulus); the exact memory update adds no restriction. Safety 0.9, and an integer number of
  // steps per output interval.
  const double dt_crit = h / std::sqrt(MU / rho);
  const long per_output = static_cast<long>(std::ceil(output_dt / (0.9 * dt_crit)));
  const double dt = output_dt / static_cast<double>(per_output);
  std::vector<MemoryStep> ms;
  for (double w : solids.omega_rad_s) ms.push_back(MemoryStep::make(w, dt));

  std::vector<double> u(ne + 1, 0.0), v(ne + 1, 0.0), mass(ne + 1, rho * h), force(ne + 1);
  mass[0] = mass[ne] = rho * h / 2;
  std::vector<double> strain(ne, 0.0), zeta(ne * L, 0.0);
  ColumnResult r;
  r.dt_s = dt;
  double t = 0.0;
  for (std::size_t k = 0; k < samples; ++k) {
    r.top_displacement_m.push_back(u[ne]);
    for (long s = 0; s < per_output; ++s) {
      std::fill(force.begin(), force.end(), 0.0);
      for (std::size_t e = 0; e < ne; ++e) {
        const double g = (u[e + 1] - u[e]) / h;
        double relax = 0.0;
        for (std::size_t l = 0; l < L; ++l) {
          double& z = zeta[e * L + l];
          if (t > 0) z = ms[l].e * z + ms[l].a * strain[e] + ms[l].c * (g - strain[e]);
          relax += solids.weight[l] * z;
        }
        strain[e] = g;
        const double sigma = MU * (g - relax);
        force[e] += sigma;
        force[e + 1] -= sigma;
      }
      force[ne] += traction(t);
      for (std::size_t i = 1; i <= ne; ++i) {  // node 0 is the fixed base
        v[i] += dt * force[i] / mass[i];
        u[i] += dt * v[i];
      }
      t += dt;
      ++r.steps;
    }
  }
  return r;
}

}  // namespace viscera::tissue
