// Free flight and free vibration: momentum is conserved exactly by central edge forces under  // SPDX-License-Identifier: Apache-2.0
// symplectic Euler; the energy-consistent GPS conserves energy, the paper form does not.
#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

struct Momenta {
  Vec3 linear = Vec3::Zero(), angular = Vec3::Zero();
};
Momenta momenta(const State& s, const std::vector<double>& m) {
  Momenta p;
  for (std::size_t i = 0; i < m.size(); ++i) {
    p.linear += m[i] * s.v[i];
    p.angular += m[i] * s.x[i].cross(s.v[i]);
  }
  return p;
}

// A deformed, spinning, drifting liver.
State initial_state(const TetMesh& mesh) {
  State s = State::at_rest(mesh);
  std::mt19937_64 rng(41);
  std::normal_distribution<double> n;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    s.x[i] += 0.0002 * Vec3(n(rng), n(rng), n(rng));
    s.v[i] = Vec3(0.05, 0, 0) + Vec3(0, 0, 2.0).cross(s.x[i]) + 0.02 * Vec3(n(rng), n(rng), n(rng));
  }
  return s;
}

}  // namespace

TEST(Conservation, FreeFlightConservesLinearAndAngularMomentum) {
  const auto mesh = test::liver2();
  const std::vector<double> rho(mesh->tet_count(), 1060.0);
  const GpsModel gps(mesh, {test::soft_tissue()});
  const GpsModel gps_volume(mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.5});
  const FiniteElementModel corotational(mesh, FeKind::corotational, {test::soft_tissue()});
  const FiniteElementModel linear(mesh, FeKind::linear, {test::soft_tissue()});
  for (const ForceModel* model : {static_cast<const ForceModel*>(&gps), static_cast<const ForceModel*>(&gps_volume),
                                  static_cast<const ForceModel*>(&corotational), static_cast<const ForceModel*>(&linear)}) {
    ExplicitIntegrator integrator(*model, rho, {});
    State s = initial_state(*mesh);
    const Momenta p0 = momenta(s, integrator.masses());
    integrator.advance(s, 200 * integrator.dt_s());
    const Momenta p1 = momenta(s, integrator.masses());
    const double dp = (p1.linear - p0.linear).norm() / p0.linear.norm();
    const double dl = (p1.angular - p0.angular).norm() / p0.angular.norm();
    std::cout << "[ figure ] " << model->name() << " free flight, 200 steps: relative change of linear momentum " << dp << ", angular momentum " << dl
              << "\n";
    EXPECT_LT(dp, 1e-12) << model->name();
    if (model != &linear)
      EXPECT_LT(dl, 1e-9) << model->name();
    else
      EXPECT_GT(dl, 1e-6) << "linear FE is not rotation invariant, so its torques do not cancel";
  }
}

TEST(Conservation, EnergyConsistentGpsConservesEnergyInFreeVibration) {
  // Cantilevered liver released from a large deformation, no damping, 0.5 s of vibration.
  const auto mesh = test::liver2();
  const std::vector<double> rho(mesh->tet_count(), 1060.0);
  const Box box = bounding_box(*mesh);
  BoundaryConditions bc;
  bc.fixed_nodes = nodes_in_box(*mesh, {box.lo, Vec3(box.lo.x() + 0.15 * (box.hi.x() - box.lo.x()), box.hi.y(), box.hi.z())});
  const GpsModel paper(mesh, {test::soft_tissue()});
  const GpsModel energy(mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.0});
  double drift[2];
  int k = 0;
  for (const GpsModel* model : {&paper, &energy}) {
    ExplicitIntegrator integrator(*model, rho, bc, {0.5});
    State s = State::at_rest(*mesh);
    // Initial shape: the free end bent down by a smooth field (edge strains up to ~15%).
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double t = (mesh->nodes[i].x() - box.lo.x()) / (box.hi.x() - box.lo.x());
      if (t > 0.15) s.x[i].z() -= 0.04 * (t - 0.15) * (t - 0.15);
    }
    const double e0 = model->energy(s.x);
    double worst = 0.0;
    std::string outcome = "bounded";
    try {
      while (s.time_s < 0.5) {
        integrator.advance(s, 0.005);
        const double e = model->energy(s.x) + integrator.kinetic_energy(s);
        worst = std::max(worst, std::abs(e - e0) / e0);
      }
    } catch (const SimulationError& e) {
      outcome = std::string("went unstable: ") + e.what();
    }
    drift[k++] = worst;
    std::cout << "[ figure ] " << model->name() << " free vibration to t = " << s.time_s << " s: max |E(t) - E0| / E0 = " << worst << "; " << outcome
              << "\n";
  }
  EXPECT_LT(drift[1], 0.02);  // bounded O(dt^2) oscillation of a symplectic integrator
  EXPECT_GT(drift[0], 10 * drift[1]);  // the non-conservative paper form pumps energy
}

TEST(Conservation, PaperGpsDoesWorkAroundAClosedLoopEnergyConsistentDoesNot) {
  // Work of the forces around a closed path in configuration space: zero for a conservative
  // force field (the gradient of an energy), non-zero for the paper form at finite strain.
  std::mt19937_64 rng(42);
  const auto rest = test::random_tet(rng);
  const auto mesh = test::single_tet_mesh(rest);
  const GpsModel paper(mesh, {test::soft_tissue()});
  const GpsModel energy(mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.0});
  Vec12 a, b;
  for (int i = 0; i < 12; ++i) {
    a(i) = std::uniform_real_distribution<double>(-1, 1)(rng);
    b(i) = std::uniform_real_distribution<double>(-1, 1)(rng);
  }
  a *= 0.003 / a.norm();
  b *= 0.003 / b.norm();
  const auto loop_work = [&](const ForceModel& m) {
    const int steps = 4000;
    double work = 0.0;
    for (int k = 0; k < steps; ++k) {  // midpoint rule over x(s) = X + a cos s + b sin s
      const double s = 2 * M_PI * (k + 0.5) / steps;
      const Vec12 u = a * std::cos(s) + b * std::sin(s);
      const Vec12 du = (-a * std::sin(s) + b * std::cos(s)) * (2 * M_PI / steps);
      std::vector<Vec3> x(rest.begin(), rest.end()), f(4, Vec3::Zero());
      for (int i = 0; i < 4; ++i) x[i] += u.segment<3>(3 * i);
      m.add_forces(x, f);
      for (int i = 0; i < 4; ++i) work += f[i].dot(du.segment<3>(3 * i));
    }
    return work;
  };
  std::vector<Vec3> peak(rest.begin(), rest.end());
  for (int i = 0; i < 4; ++i) peak[i] += a.segment<3>(3 * i);
  const double scale = energy.energy(peak);
  const double w_paper = loop_work(paper) / scale, w_energy = loop_work(energy) / scale;
  std::cout << "[ figure ] work around a closed loop / strain energy: paper GPS " << w_paper << ", energy-consistent GPS " << w_energy << "\n";
  EXPECT_LT(std::abs(w_energy), 1e-6);
  EXPECT_GT(std::abs(w_paper), 1e-4);
}
