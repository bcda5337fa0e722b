// A beam in pure bending against its exact 3D elasticity solution, converging under refinement.  // SPDX-License-Identifier: Apache-2.0
// Beam along z, bending about y with curvature kappa: sigma_zz = E kappa x, all other stresses
// zero, and (Saint-Venant) u_x = -kappa (z^2 + nu (x^2 - y^2)) / 2, u_y = -kappa nu x y,
// u_z = kappa x z, exact on any prismatic section with a traction-free lateral surface. Both end
// faces get the exact displacement; the bending moment at the base is M = E I kappa.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

constexpr double kHalfWidth = 0.005, kLength = 0.04, kCurvature = 1e-3;  // [m], [m], [1/m]
constexpr double kE = 5e3, kNu = 0.3;

Vec3 exact_displacement(const Vec3& X) {
  const double x = X.x(), y = X.y(), z = X.z();
  return Vec3(-kCurvature * (z * z + kNu * (x * x - y * y)) / 2, -kCurvature * kNu * x * y, kCurvature * x * z);
}

struct Result {
  double displacement_error, moment_error;
  std::size_t tets;
};

Result solve(const ForceModel& model, const TetMesh& mesh) {
  std::vector<std::int32_t> base, ends;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const double z = mesh.nodes[i].z();
    if (z < 1e-12) base.push_back(static_cast<std::int32_t>(i));
    if (z < 1e-12 || z > kLength - 1e-12) ends.push_back(static_cast<std::int32_t>(i));
  }
  BoundaryConditions bc;
  bc.prescribed.push_back({ends, [](const Vec3& X, double) { return Vec3(X + exact_displacement(X)); }});
  ImplicitIntegrator solver(model, std::vector<double>(mesh.tet_count(), 1000.0), bc, {1.0, 0.0, 1e-10, 30});
  State s = State::at_rest(mesh);
  solver.solve_static(s);
  double err = 0.0, ref = 0.0;  // RMS over nodes
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    err += (s.x[i] - mesh.nodes[i] - exact_displacement(mesh.nodes[i])).squaredNorm();
    ref += exact_displacement(mesh.nodes[i]).squaredNorm();
  }
  std::vector<Vec3> f(mesh.nodes.size(), Vec3::Zero());
  model.add_forces(s.x, f);
  double moment = 0.0;  // reaction moment about y at the base: sum of x f_z (see header)
  for (auto i : base) moment += mesh.nodes[i].x() * f[i].z();
  const double I = (2 * kHalfWidth) * std::pow(2 * kHalfWidth, 3) / 12;
  return {std::sqrt(err / ref), std::abs(moment / (kE * I * kCurvature) - 1.0), mesh.tet_count()};
}

void check_convergence(const char* name, const std::function<std::unique_ptr<ForceModel>(std::shared_ptr<TetMesh>)>& make) {
  std::vector<Result> r;
  for (int n : {1, 2, 4}) {
    auto mesh =
        std::make_shared<TetMesh>(make_box_mesh(Vec3(-kHalfWidth, -kHalfWidth, 0), Vec3(kHalfWidth, kHalfWidth, kLength), 2 * n, 2 * n, 8 * n));
    r.push_back(solve(*make(mesh), *mesh));
  }
  for (std::size_t k = 0; k < r.size(); ++k) {
    std::cout << "[ figure ] pure bending, " << name << ", " << r[k].tets << " tets: RMS displacement error " << r[k].displacement_error
              << ", base moment error " << r[k].moment_error;
    if (k > 0)
      std::cout << "; convergence rates " << std::log2(r[k - 1].displacement_error / r[k].displacement_error) << " (displacement), "
                << std::log2(r[k - 1].moment_error / r[k].moment_error) << " (moment)";
    std::cout << "\n";
  }
  EXPECT_GT(std::log2(r[1].displacement_error / r[2].displacement_error), 1.6) << name;  // O(h^2)
  EXPECT_GT(std::log2(r[1].moment_error / r[2].moment_error), 1.6) << name;
  EXPECT_LT(r.back().displacement_error, 0.05) << name;
}

Mat6 material() { return elasticity_matrix(IsotropicElasticity{kE, kNu}); }

}  // namespace

TEST(BeamConvergence, LinearFeConvergesToPureBending) {
  check_convergence("linear", [](auto mesh) { return std::make_unique<FiniteElementModel>(mesh, FeKind::linear, std::vector<Mat6>{material()}); });
}

TEST(BeamConvergence, GpsConvergesToPureBending) {
  check_convergence("gps", [](auto mesh) { return std::make_unique<GpsModel>(mesh, std::vector<Mat6>{material()}); });
}
