#include "viscera/tissue/integrator/mass_scaling.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "viscera/tissue/integrator/stable_step.hpp"

namespace viscera::tissue {

MassScaling scale_small_element_masses(const ForceModel& model, std::span<const double> density_kg_m3, double added_mass_fraction) {
  if (!(added_mass_fraction >= 0 && added_mass_fraction <= 10))
    throw std::invalid_argument("scale_small_element_masses: added mass fraction " + std::to_string(added_mass_fraction) + " is outside [0, 10]");
  const std::vector<double> omega = element_frequencies(model, density_kg_m3);
  const std::size_t n = omega.size();
  std::vector<double> mass(n);
  double total = 0;
  const auto& rest = model.rest_mesh().nodes;
  for (std::size_t e = 0; e < n; ++e) {
    const auto x = model.gather(rest, e);
    mass[e] = density_kg_m3[e] * signed_volume(x[0], x[1], x[2], x[3]);
    total += mass[e];
  }
  MassScaling out;
  out.density_kg_m3.assign(density_kg_m3.begin(), density_kg_m3.end());
  out.min_element_step_s = 2.0 / *std::max_element(omega.begin(), omega.end());
  if (added_mass_fraction == 0) return out;
  // Mass added for a threshold T: sum over elements with 2/omega_e < T of m_e ((T omega_e/2)^2 - 1),
  // continuous and increasing in T. Bisection in T to the requested mass.
  const double target = added_mass_fraction * total;
  const auto added = [&](double T) {
    double a = 0;
    for (std::size_t e = 0; e < n; ++e) {
      const double r = 0.5 * T * omega[e];
      if (r > 1) a += mass[e] * (r * r - 1);
    }
    return a;
  };
  double lo = out.min_element_step_s, hi = 2 * lo;
  while (added(hi) < target) hi *= 2;
  for (int it = 0; it < 100 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (added(mid) < target ? lo : hi) = mid;
  }
  const double T = lo;  // the mass added is at most the fraction
  double sum = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const double r = 0.5 * T * omega[e];
    if (r <= 1) continue;
    out.density_kg_m3[e] *= r * r;
    sum += mass[e] * (r * r - 1);
    ++out.scaled_elements;
  }
  out.added_mass_fraction = sum / total;
  out.min_element_step_s = T;
  return out;
}

double hold_element_steps(const ForceModel& model, std::span<double> density_kg_m3, std::span<const std::int32_t> elements, double min_step_s) {
  if (density_kg_m3.size() != model.element_count()) throw std::invalid_argument("hold_element_steps: one density per element expected");
  double added = 0.0;
  const auto& rest = model.rest_mesh().nodes;
  for (const std::int32_t element : elements) {
    const auto e = static_cast<std::size_t>(element);
    // Only the elements whose frequency exceeds 2 / min_step_s are scaled: the others are told
    // from a bound, without their eigenvalues (a cut's children, at the physics thread's cost).
    const double r = 0.5 * min_step_s * element_frequency_above(model, e, density_kg_m3[e], 2.0 / min_step_s);
    if (r <= 1.0) continue;
    const auto x = model.gather(rest, e);
    added += density_kg_m3[e] * (r * r - 1.0) * signed_volume(x[0], x[1], x[2], x[3]);
    density_kg_m3[e] *= r * r;
  }
  return added;
}

}  // namespace viscera::tissue
