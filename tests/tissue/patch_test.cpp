// Patch test: a homogeneous strain imposed on the boundary of an irregular mesh gives a uniform  // SPDX-License-Identifier: Apache-2.0
// stress inside, solved by the implicit machinery (static Newton + CHOLMOD).
#include <gtest/gtest.h>

#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

std::shared_ptr<TetMesh> irregular_box() {
  auto m = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.04, 0.03, 0.05), 4, 3, 5));
  const auto boundary = extract_boundary(*m).nodes;
  std::vector<char> on_boundary(m->nodes.size(), 0);
  for (auto i : boundary) on_boundary[i] = 1;
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t i = 0; i < m->nodes.size(); ++i)
    if (!on_boundary[i]) m->nodes[i] += 0.0025 * Vec3(u(rng), u(rng), u(rng));  // 25% of h
  validate_mesh(*m);
  return m;
}

// Imposes x = A X on the boundary, solves for equilibrium, returns max over tets of
// |sigma_tet - sigma_exact| / |sigma_exact| with sigma measured in the frame `R` rotates to.
double patch_error(const ForceModel& model, const TetMesh& mesh, const Mat3& A, const Mat3& R, const Vec6& sigma_exact, int* iterations) {
  BoundaryConditions bc;
  bc.prescribed.push_back({extract_boundary(mesh).nodes, [A](const Vec3& X, double) { return Vec3(A * X); }});
  ImplicitIntegrator solver(model, std::vector<double>(mesh.tet_count(), 1000.0), bc, {1.0, 0.0, 1e-11, 30});
  State s = State::at_rest(mesh);
  for (auto& p : s.x) p = R * p;  // start from the rigid rotation: the solver finds the strain
  const NewtonReport rep = solver.solve_static(s);
  *iterations = rep.iterations;
  const FiniteElementModel probe(std::make_shared<TetMesh>(mesh), FeKind::linear, {test::soft_tissue()});
  // Measure the strain of every tet after undoing the rotation, then its stress with D.
  std::vector<Vec3> unrotated = s.x;
  for (auto& p : unrotated) p = R.transpose() * p;
  double worst = 0.0;
  for (std::size_t e = 0; e < mesh.tet_count(); ++e)
    worst = std::max(worst, (probe.element_stress(unrotated, e) - sigma_exact).norm() / sigma_exact.norm());
  return worst;
}

}  // namespace

TEST(PatchTest, UniformStressInsideForEveryModel) {
  const auto mesh = irregular_box();
  const Mat6 D = test::soft_tissue();
  Mat3 E;
  E << 1.0, 0.3, -0.2, 0.3, -0.5, 0.4, -0.2, 0.4, 0.7;
  const FiniteElementModel linear(mesh, FeKind::linear, {D});
  const FiniteElementModel corotational(mesh, FeKind::corotational, {D});
  const GpsModel gps(mesh, {D});
  const GpsModel gps_energy(mesh, {D}, {}, {GpsVariant::energy_consistent, 0.5});
  struct Case {
    const ForceModel* model;
    double strain, degrees, tolerance;
  } cases[] = {
      {&linear, 1e-3, 0.0, 1e-9},  // linear FE passes the patch test exactly
      {&corotational, 1e-3, 40.0, 1e-9},  // and corotational FE under a finite rotation too
      {&gps, 1e-6, 40.0, 1e-5},  // the GPS only at small strain (error O(strain))
      {&gps_energy, 1e-6, 40.0, 1e-5},
  };
  for (const auto& c : cases) {
    const Mat3 R = Eigen::AngleAxisd(c.degrees * M_PI / 180, Vec3(1, 1, 0).normalized()).toRotationMatrix();
    const Mat3 strain = c.strain * E;
    const Vec6 sigma = D * strain_to_voigt(strain);
    int iterations = 0;
    const double err = patch_error(*c.model, *mesh, R * (Mat3::Identity() + strain), R, sigma, &iterations);
    std::cout << "[ figure ] patch test " << c.model->name() << " (strain " << c.strain << ", rotation " << c.degrees
              << " deg): max relative stress deviation " << err << " after " << iterations << " Newton iterations\n";
    EXPECT_LT(err, c.tolerance) << c.model->name();
  }
}
