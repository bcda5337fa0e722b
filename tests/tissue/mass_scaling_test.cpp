// Selective mass scaling (mass_scaling.hpp) against theory: the added mass as stated, the true  // SPDX-License-Identifier: Apache-2.0
// stable step it reaches, the weight kept physical, the lowest frequency as the Rayleigh quotient of
// the unscaled mode predicts, on a box and on the server's 12k liver.
#include "viscera/tissue/integrator/mass_scaling.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/refinement.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

#include "integrator_reference.hpp"
#include "test_support.hpp"

using namespace viscera::tissue;
using namespace viscera::tissue::integrator_reference;
namespace test = viscera::tissue::test;

TEST(MassScaling, AddsTheStatedMassAndTheTrueStableStepReachesTheElementThreshold) {
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  const ExplicitIntegrator plain(gps, s.rho(), {});
  ExplicitOptions o;
  o.added_mass_fraction = 0.02;
  const ExplicitIntegrator scaled(gps, s.rho(), {}, o);
  const MassScaling& ms = scaled.mass_scaling();
  double m0 = 0, m1 = 0;
  for (double m : plain.masses()) m0 += m;
  for (double m : scaled.masses()) m1 += m;
  EXPECT_NEAR(m1 / m0 - 1, 0.02, 1e-9);
  EXPECT_NEAR(ms.added_mass_fraction, 0.02, 1e-9);
  // Each element: step 2/omega_e (recomputed with its new density) at least the threshold; the
  // elements that were already slower keep their density.
  const std::vector<double> before = element_frequencies(gps, s.rho());
  const std::vector<double> after = element_frequencies(gps, ms.density_kg_m3);
  std::size_t heavier = 0;
  for (std::size_t e = 0; e < after.size(); ++e) {
    EXPECT_GE(2 / after[e], ms.min_element_step_s * (1 - 1e-9)) << "element " << e;
    if (2 / before[e] >= ms.min_element_step_s)
      EXPECT_EQ(ms.density_kg_m3[e], 1060.0) << "element " << e;
    else
      ++heavier;
  }
  EXPECT_EQ(heavier, ms.scaled_elements);
  EXPECT_GT(heavier, 0u);
  EXPECT_LT(heavier, after.size());
  const double exact_plain = true_critical_step(*s.mesh, plain.masses(), test::soft_tissue());
  const double exact_scaled = true_critical_step(*s.mesh, scaled.masses(), test::soft_tissue());
  std::cout << "[ figure ] liver (596 tets): +2% mass on " << heavier << " of " << after.size() << " elements: true critical step " << exact_plain
            << " -> " << exact_scaled << " s (x" << exact_scaled / exact_plain << "), element threshold " << ms.min_element_step_s << " s\n";
  EXPECT_GE(exact_scaled, ms.min_element_step_s);  // omega_max <= max_e omega_e (Irons)
  EXPECT_GT(exact_scaled, exact_plain);
  // The integrator's own step follows the new masses (element bound on the new densities).
  EXPECT_NEAR(scaled.critical_step().dt_s, 2 / *std::max_element(after.begin(), after.end()), 1e-12);
  EXPECT_THROW(scale_small_element_masses(gps, s.rho(), -0.1), std::invalid_argument);
}

TEST(MassScaling, WeightStaysPhysicalSoTheOrganSettlesWhereTheStaticSolutionIs) {
  // Mass does not enter equilibrium and the added mass is inertia only (weight stays m g): the
  // damped explicit run with 5% added mass settles on the implicit static solution without it.
  Fixture s;
  const Mat6 D = elasticity_matrix(IsotropicElasticity{50e3, 0.45});  // sags a few mm, not a slump
  const GpsModel gps(s.mesh, {D}, {}, {GpsVariant::energy_consistent, 0.0});
  BoundaryConditions bc;
  const Box box = bounding_box(*s.mesh);
  bc.fixed_nodes = nodes_in_box(*s.mesh, {box.lo, Vec3(box.lo.x() + 0.2 * (box.hi.x() - box.lo.x()), box.hi.y(), box.hi.z())});
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  ImplicitIntegrator implicit(gps, s.rho(), bc);
  State reference = State::at_rest(*s.mesh);
  ASSERT_TRUE(implicit.solve_static(reference).converged);
  ExplicitOptions o;
  o.added_mass_fraction = 0.05;
  o.mass_damping_per_s = 60;  // near critical for the lowest mode: settles in a fraction of a second
  ExplicitIntegrator scaled(gps, s.rho(), bc, o);
  State st = State::at_rest(*s.mesh);
  scaled.advance(st, 1.5);
  double err = 0, sag = 0;
  for (std::size_t i = 0; i < st.x.size(); ++i) {
    err = std::max(err, (st.x[i] - reference.x[i]).norm());
    sag = std::max(sag, (reference.x[i] - s.mesh->nodes[i]).norm());
  }
  std::cout << "[ figure ] liver (596 tets) hanging, +5% mass: largest sag " << sag << " m, explicit rest vs static solution " << err << " m\n";
  EXPECT_GT(sag, 1e-3);
  EXPECT_LT(err, 1e-4 * sag);
}

TEST(MassScaling, LowestFrequencyDropsAsTheRayleighQuotientOfTheUnscaledModePredicts) {
  // Theory: with M' = M + dM >= M, the unscaled lowest mode u is a trial vector for the scaled
  // problem, so omega1'^2 <= u^T K u / u^T M' u = omega1^2 / (1 + delta), delta = u^T dM u / u^T M u;
  // to first order in the perturbation the two are equal.
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  BoundaryConditions bc;
  const Box box = bounding_box(*s.mesh);
  bc.fixed_nodes = nodes_in_box(*s.mesh, {box.lo, Vec3(box.lo.x() + 0.2 * (box.hi.x() - box.lo.x()), box.hi.y(), box.hi.z())});
  const ExplicitIntegrator plain(gps, s.rho(), bc);
  ExplicitOptions o;
  o.added_mass_fraction = 0.05;
  const ExplicitIntegrator scaled(gps, s.rho(), bc, o);
  const auto [w0, u0] = lowest_mode(*s.mesh, plain.masses(), test::soft_tissue(), bc.fixed_nodes);
  const auto [w1, u1] = lowest_mode(*s.mesh, scaled.masses(), test::soft_tissue(), bc.fixed_nodes);
  const double delta = mass_norm2(u0, scaled.masses()) / mass_norm2(u0, plain.masses()) - 1;
  const double bound = w0 / std::sqrt(1 + delta);
  std::cout << "[ figure ] liver (596 tets), +5% mass on the smallest elements: lowest frequency " << w0 / (2 * M_PI) << " -> " << w1 / (2 * M_PI)
            << " Hz (" << 100 * (w1 / w0 - 1) << "%; uniform +5% would give " << 100 * (1 / std::sqrt(1.05) - 1) << "%), Rayleigh bound "
            << bound / (2 * M_PI) << " Hz\n";
  EXPECT_LE(w1, bound * (1 + 1e-10));
  EXPECT_LT(w1, w0);
  EXPECT_NEAR(w0 - w1, w0 - bound, 0.05 * (w0 - bound));  // first order: the drop is the bound's drop
}

TEST(MassScaling, OnTheServersTwelveThousandTetLiverTheStepGrowsAndTheLowestFrequencyDropsAsPredicted) {
  // The bundled 12k liver scene's organ (liver2 refined once, held by its lower surface, the
  // viscoelastic liver's unrelaxed stiffness, GPS energy form, global step estimate): the figures
  // behind the scene's added_mass_fraction. Lowest frequency by inverse iteration on the
  // CHOLMOD-factorised rest stiffness; the same Rayleigh bound as above.
  auto mesh = test::liver2();
  *mesh = refine_uniform(*mesh);
  const Material material = read_material_file(test::data_path("materials/liver-viscoelastic.json"));
  const ViscoelasticSetup ve = make_viscoelastic(material.elasticity, *material.viscoelasticity);
  const auto model = make_force_model("gps_energy", mesh, {ve.unrelaxed_elasticity}, 0.5, ve.gps);
  BoundaryConditions bc;
  Box slab = bounding_box(*mesh);
  slab.hi.z() = slab.lo.z() + 0.2 * (slab.hi.z() - slab.lo.z());
  bc.fixed_nodes = surface_nodes_in_box(*mesh, slab);
  const std::vector<double> rho(mesh->tet_count(), material.density_kg_m3);
  ExplicitOptions o{0.85, 0.0, 2.0, 2.0, true, 0.0};
  const ExplicitIntegrator plain(*model, rho, bc, o);
  o.added_mass_fraction = 0.05;
  const ExplicitIntegrator scaled(*model, rho, bc, o);
  ImplicitIntegrator stiffness(*model, rho, bc);
  ASSERT_TRUE(stiffness.factorize_stiffness(mesh->nodes));
  const auto lowest = [&](const std::vector<double>& m, std::vector<Vec3>& u) {
    std::vector<Vec3> f(u.size()), w(u.size());
    double omega2 = 0;
    for (int it = 0; it < 200; ++it) {
      for (std::size_t i = 0; i < u.size(); ++i) f[i] = m[i] * u[i];
      stiffness.compliance(f, w);  // w = K^-1 M u
      double wmu = 0, wmw = 0;
      for (std::size_t i = 0; i < u.size(); ++i) {
        wmu += m[i] * w[i].dot(u[i]);
        wmw += m[i] * w[i].squaredNorm();
      }
      omega2 = wmu / wmw;  // Rayleigh quotient of w: w^T K w / w^T M w
      for (std::size_t i = 0; i < u.size(); ++i) u[i] = w[i] / std::sqrt(wmw);
    }
    return std::sqrt(omega2);
  };
  std::vector<Vec3> u0(mesh->node_count(), Vec3(0.3, 0.5, 0.8)), u1 = u0;
  const double w0 = lowest(plain.masses(), u0);
  const double w1 = lowest(scaled.masses(), u1);
  double mu = 0, mpu = 0;
  for (std::size_t i = 0; i < u0.size(); ++i) {
    mu += plain.masses()[i] * u0[i].squaredNorm();
    mpu += scaled.masses()[i] * u0[i].squaredNorm();
  }
  const double bound = w0 / std::sqrt(mpu / mu);
  const MassScaling& ms = scaled.mass_scaling();
  std::cout << "[ figure ] 12k liver scene, +" << 100 * ms.added_mass_fraction << "% mass on " << ms.scaled_elements << " of " << mesh->tet_count()
            << " elements: stable step (global estimate) " << plain.critical_step().dt_s << " -> " << scaled.critical_step().dt_s << " s (x"
            << scaled.critical_step().dt_s / plain.critical_step().dt_s << "); lowest frequency " << w0 / (2 * M_PI) << " -> " << w1 / (2 * M_PI)
            << " Hz (" << 100 * (w1 / w0 - 1) << "%)\n";
  EXPECT_LE(w1, bound * (1 + 1e-8));
  EXPECT_NEAR(w0 - w1, w0 - bound, 0.05 * (w0 - bound) + 1e-9 * w0);
  EXPECT_GT(scaled.critical_step().dt_s, 2 * plain.critical_step().dt_s);
}
