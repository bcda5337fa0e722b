#include "integrator/stable_step.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace viscera::tissue {

StableStep critical_time_step(const ForceModel& model, std::span<const double> density_kg_m3) {
  if (density_kg_m3.size() != model.element_count())
    throw std::invalid_argument("critical_time_step: one density per element expected");
  const auto& rest = model.rest_mesh().nodes;
  double worst = 0.0;
  std::size_t worst_element = 0;
  for (std::size_t e = 0; e < model.element_count(); ++e) {
    const auto x = model.gather(rest, e);
    const double volume = signed_volume(x[0], x[1], x[2], x[3]);
    const Mat12 K = model.element_tangent(rest, e);
    const Mat12 Ks = 0.5 * (K + K.transpose());
    const double lambda =
        Eigen::SelfAdjointEigenSolver<Mat12>(Ks, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
    const double omega2 = lambda / (0.25 * density_kg_m3[e] * volume);
    if (omega2 > worst) {
      worst = omega2;
      worst_element = e;
    }
  }
  const double omega = std::sqrt(worst);
  // Stiffness-proportional damping (Kelvin-Voigt, time tau) shortens the step of central
  // differences to (2 / omega) (sqrt(1 + xi^2) - xi), xi = tau omega / 2 (Belytschko et al.).
  const double xi = 0.5 * model.stiffness_damping_time_s() * omega;
  return {2.0 / omega * (std::sqrt(1.0 + xi * xi) - xi), omega, worst_element};
}

}  // namespace viscera::tissue
