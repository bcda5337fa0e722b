// Integrators against theory: the computed stable step versus the true global limit 2/omega_max,  // SPDX-License-Identifier: Apache-2.0
// instability detected at the limit, backward Euler against a dense solve, static equilibrium.
#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/fem/finite_element_model.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/integrator/mass_scaling.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/refinement.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

#include "integrator_reference.hpp"
#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

using namespace viscera::tissue::integrator_reference;

TEST(StableStep, IsSafeAndNoMoreConservativeThanTheWorstElementsRayleighBound) {
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  const ExplicitIntegrator integrator(gps, s.rho(), {});
  const double exact = true_critical_step(*s.mesh, integrator.masses(), test::soft_tissue());
  const double computed = integrator.critical_step().dt_s;
  std::cout << "[ figure ] liver (596 tets): element-bound critical step " << computed << " s, true global " << exact << " s, ratio "
            << computed / exact << "\n";
  EXPECT_LE(computed, exact * (1 + 1e-9));
  // How conservative it may be: the worst element's own highest mode phi (of K_e with its lumped
  // share rho V_e / 4 per vertex), extended by zero, has a Rayleigh quotient phi^T K phi / phi^T M phi
  // on the whole organ that is at most the true omega_max^2 (Rayleigh), while the element bound is
  // lambda_e = phi^T K_e phi / phi^T M_e phi. So computed / exact >= sqrt(quotient / lambda_e).
  const std::size_t e = integrator.critical_step().element;
  const Tet& t = s.mesh->tets[e];
  const std::array<Vec3, 4> x{s.mesh->nodes[t[0]], s.mesh->nodes[t[1]], s.mesh->nodes[t[2]], s.mesh->nodes[t[3]]};
  const double share = 0.25 * 1060.0 * signed_volume(x[0], x[1], x[2], x[3]);
  const Eigen::SelfAdjointEigenSolver<Mat12> element(linear_fe_stiffness(x, test::soft_tissue()) / share);
  const Eigen::Matrix<double, 12, 1> phi = element.eigenvectors().col(11);
  const double lambda_e = element.eigenvalues()(11);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * s.mesh->node_count()));
  double phi_M_phi = 0;
  for (int k = 0; k < 4; ++k) {
    u.segment<3>(3 * t[k]) = phi.segment<3>(3 * k);
    phi_M_phi += integrator.masses()[static_cast<std::size_t>(t[k])] * phi.segment<3>(3 * k).squaredNorm();
  }
  const double quotient = u.dot(dense_stiffness(*s.mesh, test::soft_tissue()) * u) / phi_M_phi;
  const double bound = std::sqrt(quotient / lambda_e);
  std::cout << "[ figure ] the worst element's mode on the whole organ: Rayleigh bound on the ratio " << bound << "\n";
  EXPECT_GE(computed / exact, bound * (1 - 1e-9));
}

TEST(StableStep, EachElementsFrequencyEqualsTheFullTwelveByTwelveEigenproblem) {
  // element_frequency solves a 6x6 problem on the deformation modes; the reference here is the
  // 12x12 eigenvalue problem of the element's tangent at rest with its lumped mass, for the models
  // a scene may choose (the GPS with its volume term, linear and corotational FE).
  Fixture s;
  for (const std::string name : {"gps", "gps_energy", "linear", "corotational"}) {
    const auto model = make_force_model(name, s.mesh, {test::soft_tissue()}, name.rfind("gps", 0) == 0 ? 0.5 : 0.0);
    double worst = 0;
    int above = 0;
    for (std::size_t e = 0; e < model->element_count(); ++e) {
      const auto x = model->gather(s.mesh->nodes, e);
      const Mat12 K = model->element_tangent(s.mesh->nodes, e);
      const double mass = 0.25 * 1060.0 * signed_volume(x[0], x[1], x[2], x[3]);
      const double full =
          std::sqrt(Eigen::SelfAdjointEigenSolver<Mat12>(0.5 * (K + K.transpose()), Eigen::EigenvaluesOnly).eigenvalues().maxCoeff() / mass);
      const double omega = element_frequency(*model, e, 1060.0);
      worst = std::max(worst, std::abs(omega - full) / full);
      // Asked whether it exceeds a frequency: the value where it may, a bound under it otherwise.
      for (const double limit : {0.5 * full, 0.999 * full, 1.001 * full, 3.0 * full}) {
        const double told = element_frequency_above(*model, e, 1060.0, limit);
        if (told > limit) {
          EXPECT_NEAR(told, full, 1e-9 * full) << name << " element " << e;
          ++above;
        } else {
          EXPECT_GE(told, full * (1 - 1e-12)) << name << " element " << e;
        }
      }
    }
    EXPECT_LT(worst, 1e-10) << name;
    EXPECT_GE(above, 2 * static_cast<int>(model->element_count())) << name;  // every element above half and 0.999 of its own
    std::cout << "[ figure ] " << name << ": element frequencies from the 6x6 problem against the 12x12 one, worst " << worst << "\n";
  }
}

TEST(StableStep, InstabilityBeyondTheLimitIsReportedWithElementAndTime) {
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  const ExplicitIntegrator probe(gps, s.rho(), {});
  const double exact = true_critical_step(*s.mesh, probe.masses(), test::soft_tissue());
  std::mt19937_64 rng(51);
  std::normal_distribution<double> n;
  State start = State::at_rest(*s.mesh);
  for (auto& p : start.x) p += 1e-6 * Vec3(n(rng), n(rng), n(rng));  // excite every mode

  // Just below the true limit: bounded for a long run.
  ExplicitIntegrator stable(gps, s.rho(), {}, {1.0, 0.97 * exact});
  State a = start;
  EXPECT_NO_THROW(stable.advance(a, 3000 * 0.97 * exact));
  double amplitude = 0;
  for (std::size_t i = 0; i < a.x.size(); ++i) amplitude = std::max(amplitude, (a.x[i] - s.mesh->nodes[i]).norm());
  EXPECT_LT(amplitude, 1e-4);

  // Just above it: the highest mode grows until the strain limit trips, reported, state intact.
  ExplicitIntegrator unstable(gps, s.rho(), {}, {1.0, 1.05 * exact});
  State b = start;
  try {
    unstable.advance(b, 3000 * 1.05 * exact);
    FAIL() << "no instability reported";
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    std::cout << "[ message ] " << msg << "\n";
    EXPECT_NE(msg.find("went unstable at t = "), std::string::npos);
    EXPECT_NE(msg.find("element "), std::string::npos);
  }
  for (const auto& p : b.x) ASSERT_TRUE(p.allFinite());
  for (const auto& v : b.v) ASSERT_TRUE(v.allFinite());
}

TEST(Implicit, BackwardEulerStepEqualsADenseSolveForLinearFe) {
  Fixture s;
  const FiniteElementModel fe(s.mesh, FeKind::linear, {test::soft_tissue()});
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  bc.fixed_nodes = nodes_in_box(*s.mesh, {bounding_box(*s.mesh).lo, bounding_box(*s.mesh).lo + Vec3(0.05, 1, 1)});
  ASSERT_FALSE(bc.fixed_nodes.empty());
  const double dt = 0.01, alpha = 2.0;
  ImplicitIntegrator implicit(fe, s.rho(), bc, {dt, alpha, 1e-12, 10});
  State st = State::at_rest(*s.mesh);
  for (auto& v : st.v) v = Vec3(0.01, -0.02, 0.03);
  for (auto i : bc.fixed_nodes) st.v[i].setZero();
  const State before = st;
  const NewtonReport rep = implicit.step(st);
  EXPECT_TRUE(rep.converged);
  EXPECT_LE(rep.iterations, 2);  // linear problem: Newton converges in one step

  // Dense: (M (1 + alpha dt) / dt^2 + K) u1 = M (1 + alpha dt) u0 / dt^2 + M v0 / dt + f_ext - K*0.
  const Eigen::MatrixXd K = dense_stiffness(*s.mesh, test::soft_tissue());
  const auto& m = implicit.masses();
  std::vector<char> fixed(s.mesh->node_count(), 0);
  for (auto i : bc.fixed_nodes) fixed[i] = 1;
  std::vector<Eigen::Index> free;
  for (std::size_t i = 0; i < fixed.size(); ++i)
    if (!fixed[i])
      for (int k = 0; k < 3; ++k) free.push_back(static_cast<Eigen::Index>(3 * i + k));
  const auto nf = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd A(nf, nf);
  Eigen::VectorXd rhs(nf);
  const double ms = (1 + alpha * dt) / (dt * dt);
  for (Eigen::Index r = 0; r < nf; ++r) {
    const std::size_t node = static_cast<std::size_t>(free[r] / 3);
    const int k = static_cast<int>(free[r] % 3);
    for (Eigen::Index c = 0; c < nf; ++c) A(r, c) = K(free[r], free[c]);
    A(r, r) += ms * m[node];
    rhs(r) = m[node] * before.v[node][k] / dt + m[node] * bc.gravity_m_s2[k];
  }
  const Eigen::VectorXd u = A.ldlt().solve(rhs);
  double err = 0, ref = 0;
  for (Eigen::Index r = 0; r < nf; ++r) {
    const std::size_t node = static_cast<std::size_t>(free[r] / 3);
    err = std::max(err, std::abs(st.x[node][free[r] % 3] - s.mesh->nodes[node][free[r] % 3] - u(r)));
    ref = std::max(ref, std::abs(u(r)));
  }
  EXPECT_LT(err, 1e-9 * ref);
}

TEST(Implicit, NewtonConvergesOnTheNonlinearGpsAndReportsIterations) {
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.5});
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  const Box box = bounding_box(*s.mesh);
  bc.fixed_nodes = nodes_in_box(*s.mesh, {box.lo, Vec3(box.lo.x() + 0.2 * (box.hi.x() - box.lo.x()), box.hi.y(), box.hi.z())});
  ImplicitIntegrator implicit(gps, s.rho(), bc, {0.05, 0.0, 1e-10, 40});
  State st = State::at_rest(*s.mesh);
  const NewtonReport rep = implicit.solve_static(st);  // large sag of a soft organ under gravity
  double sag = 0;
  for (std::size_t i = 0; i < st.x.size(); ++i) sag = std::max(sag, s.mesh->nodes[i].z() - st.x[i].z());
  std::cout << "[ figure ] static sag of a cantilevered liver under gravity: " << sag << " m in " << rep.iterations << " Newton iterations, residual "
            << rep.residual_n << " N of " << rep.force_scale_n << " N\n";
  EXPECT_TRUE(rep.converged);
  EXPECT_GT(sag, 0.0);
  // Equilibrium check by another path: total reaction at the fixed nodes balances the weight.
  std::vector<Vec3> f(st.x.size(), Vec3::Zero());
  gps.add_forces(st.x, f);
  Vec3 reaction = Vec3::Zero();
  double weight = 0;
  for (auto i : bc.fixed_nodes) reaction -= f[i];
  for (double m : implicit.masses()) weight += m * 9.81;
  double fixed_weight = 0;
  for (auto i : bc.fixed_nodes) fixed_weight += implicit.masses()[i] * 9.81;
  EXPECT_NEAR(reaction.z(), weight - fixed_weight, 1e-6 * weight);
}

TEST(StableStep, GlobalEstimateIsCloseToTheTrueLimitFromBelowWithItsMargin) {
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  ExplicitOptions o;
  o.global_stable_step = true;
  const ExplicitIntegrator integrator(gps, s.rho(), {}, o);
  const double exact = true_critical_step(*s.mesh, integrator.masses(), test::soft_tissue());
  const double estimate = integrator.critical_step().dt_s;
  std::cout << "[ figure ] liver (596 tets): global estimate of the critical step " << estimate << " s, true " << exact << " s, ratio "
            << estimate / exact << "\n";
  EXPECT_LE(estimate, exact);  // the margin covers the Rayleigh quotient's underestimate
  EXPECT_GT(estimate, 0.9 * exact);  // and costs little
  // At the safety factor 0.9 of the estimate the run is stable.
  ExplicitIntegrator run(gps, s.rho(), {}, o);
  State st = State::at_rest(*s.mesh);
  std::mt19937_64 rng(52);
  std::normal_distribution<double> n;
  for (auto& p : st.x) p += 1e-6 * Vec3(n(rng), n(rng), n(rng));
  EXPECT_NO_THROW(run.advance(st, 3000 * run.dt_s()));
}

TEST(Explicit, StiffForceFieldSpringsAreTakenImplicitlyAndReachTheExactEquilibrium) {
  // Every node tied to its rest position by a spring 100x stiffer than its own mass allows at the
  // step (dt^2 k / m = 100 on the lightest node): reported to the integrator, the run stays stable
  // and settles on the dense static solution (K + k I) u = M g; not reported, it blows up.
  Fixture s;
  const FiniteElementModel fe(s.mesh, FeKind::linear, {test::soft_tissue()});
  const ExplicitOptions o{0.85, 0.0, 400.0};
  const ExplicitIntegrator probe(fe, s.rho(), {}, o);
  const double m_min = *std::min_element(probe.masses().begin(), probe.masses().end());
  const double k = 100.0 * m_min / (probe.dt_s() * probe.dt_s());
  const auto& rest = s.mesh->nodes;
  const auto springs = [&](bool report) {
    return [&, report](const BoundaryConditions::FieldEvaluation& e) {
      for (std::size_t i = 0; i < e.x.size(); ++i) {
        e.f[i] += k * (rest[i] - e.x[i]);
        if (report) e.stiffness[i] += k;
      }
    };
  };
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  bc.force_field = springs(true);
  ExplicitIntegrator run(fe, s.rho(), bc, o);
  State st = State::at_rest(*s.mesh);
  EXPECT_NO_THROW(run.advance(st, 0.2));

  Eigen::MatrixXd A = dense_stiffness(*s.mesh, test::soft_tissue());
  Eigen::VectorXd rhs(A.rows());
  for (Eigen::Index r = 0; r < A.rows(); ++r) {
    A(r, r) += k;
    rhs(r) = run.masses()[static_cast<std::size_t>(r / 3)] * bc.gravity_m_s2[r % 3];
  }
  const Eigen::VectorXd u = A.ldlt().solve(rhs);
  double err = 0;
  for (std::size_t i = 0; i < rest.size(); ++i)
    for (int c = 0; c < 3; ++c) err = std::max(err, std::abs(st.x[i][c] - rest[i][c] - u(static_cast<Eigen::Index>(3 * i + c))));
  std::cout << "[ figure ] springs with dt^2 k / m_min = 100: explicit equilibrium off the dense solve by " << err / u.cwiseAbs().maxCoeff()
            << " of the largest displacement " << u.cwiseAbs().maxCoeff() << " m\n";
  EXPECT_LT(err, 1e-6 * u.cwiseAbs().maxCoeff());

  bc.force_field = springs(false);
  ExplicitIntegrator blind(fe, s.rho(), bc, o);
  State sb = State::at_rest(*s.mesh);
  EXPECT_THROW(blind.advance(sb, 0.05), SimulationError);
}

TEST(Explicit, FieldDashpotsAreTakenImplicitlyLikeBackwardEulerInTheVelocity) {
  // Every node under a dashpot c_i = gamma m_i with dt gamma = 100, the mesh moving as a rigid
  // body (no elastic force): reported to the integrator, each step multiplies the velocity by
  // 1 / (1 + dt gamma), backward Euler's factor, exactly; not reported (forward Euler in the
  // dashpot), it grows by |1 - dt gamma| = 99 per step and the run blows up.
  Fixture s;
  const FiniteElementModel fe(s.mesh, FeKind::linear, {test::soft_tissue()});
  const ExplicitIntegrator probe(fe, s.rho(), {});
  const double dt = probe.dt_s(), gamma = 100.0 / dt;
  const auto dashpots = [&](bool report) {
    return [&, report](const BoundaryConditions::FieldEvaluation& e) {
      for (std::size_t i = 0; i < e.x.size(); ++i) {
        e.f[i] -= gamma * probe.masses()[i] * e.v[i];
        if (report) e.damping[i] += gamma * probe.masses()[i];
      }
    };
  };
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3::Zero();
  bc.force_field = dashpots(true);
  ExplicitIntegrator run(fe, s.rho(), bc);
  State st = State::at_rest(*s.mesh);
  for (auto& v : st.v) v = Vec3(0.01, -0.02, 0.005);
  for (int k = 0; k < 3; ++k) run.step(st);
  const double factor = std::pow(1.0 / (1.0 + dt * gamma), 3);
  const Vec3 v0(0.01, -0.02, 0.005);
  for (const auto& v : st.v) EXPECT_NEAR((v - factor * v0).norm(), 0.0, 1e-6 * factor * v0.norm());  // elastic round-off of the translation
  bc.force_field = dashpots(false);
  ExplicitIntegrator blind(fe, s.rho(), bc);
  State sb = State::at_rest(*s.mesh);
  for (auto& v : sb.v) v = Vec3(0.01, -0.02, 0.005);
  EXPECT_THROW(blind.advance(sb, 20 * dt), SimulationError);
}

TEST(Explicit, FieldSpringsAtTheEndOfStepExtensionAreBackwardEulerAndNeverGainEnergy) {
  // The mesh translating rigidly (no elastic force) between two walls at +-a along x, each node
  // pushed back by a stiff penalty spring k_i = kappa m_i beyond them. Evaluated as
  // FieldEvaluation asks (at the extension predicted for the end of the step, stiffness reported),
  // one step inside a wall is backward Euler exactly: (1 + dt^2 kappa) v' = v - dt kappa d. Physical
  // contact conserves the energy of the bounce; backward Euler may only remove some, at every
  // ratio dt^2 kappa (it removes most of it within a few bounces here). Springs taken at their
  // current extension with the added mass only gain: 8% and 57% over the same run.
  Fixture s;
  const FiniteElementModel fe(s.mesh, FeKind::linear, {test::soft_tissue()});
  const ExplicitIntegrator probe(fe, s.rho(), {});
  const double dt = probe.dt_s(), speed = 0.01, a = 50 * speed * dt;  // 100 steps from wall to wall
  const auto& X = s.mesh->nodes;
  for (const double q : {0.3, 2.0}) {  // dt^2 kappa
    const double kappa = q / (dt * dt);
    BoundaryConditions bc;
    bc.gravity_m_s2 = Vec3::Zero();
    bc.force_field = [&](const BoundaryConditions::FieldEvaluation& e) {
      for (std::size_t i = 0; i < e.x.size(); ++i)
        for (const double side : {1.0, -1.0}) {
          const double depth = side * (e.x[i].x() - X[i].x()) - a;
          if (depth <= 0) continue;
          const double k = kappa * probe.masses()[i];
          e.f[i].x() -= side * std::max(0.0, k * (depth + e.dt_s * side * e.v[i].x()));  // pushes, never pulls
          e.stiffness[i] += k;
        }
    };
    ExplicitIntegrator run(fe, s.rho(), bc, ExplicitOptions{0.9, dt});
    // One step from inside the right wall, moving further in.
    State st = State::at_rest(*s.mesh);
    const double d0 = 0.3 * a, v0 = speed;
    for (std::size_t i = 0; i < X.size(); ++i) {
      st.x[i].x() += a + d0;
      st.v[i] = Vec3(v0, 0, 0);
    }
    run.step(st);
    const double v1 = (v0 - dt * kappa * d0) / (1 + q);
    for (const auto& v : st.v) EXPECT_NEAR(v.x(), v1, 1e-9 * speed) << q;
    // Bouncing from the centre: the kinetic energy between contacts never exceeds the first.
    State b = State::at_rest(*s.mesh);
    for (auto& v : b.v) v = Vec3(speed, 0, 0);
    const double e0 = run.kinetic_energy(b);
    double highest = 0;
    int reversals = 0;
    double last_v = speed;
    for (int k = 0; k < 3000; ++k) {
      run.step(b);
      const double u = b.x[0].x() - X[0].x();
      if (b.v[0].x() * last_v < 0) ++reversals;
      if (b.v[0].x() != 0) last_v = b.v[0].x();
      if (std::abs(u) < a && std::abs(u - dt * b.v[0].x()) < a) highest = std::max(highest, run.kinetic_energy(b));
    }
    std::cout << "[ figure ] dt^2 kappa " << q << ": " << reversals << " velocity reversals, highest kinetic energy between contacts " << highest / e0
              << " of the first, last " << run.kinetic_energy(b) / e0 << "\n";
    EXPECT_GE(reversals, 3) << q;
    EXPECT_LE(highest, e0 * (1 + 1e-9)) << q;
  }
}

TEST(Explicit, AdvanceUsesEqualSubStepsSoTicksNotAMultipleOfTheStepStayStable) {
  // A tick of 4.07 dt taken as 4 dt + 0.07 dt breaks symplectic Euler's staggering and pumps
  // energy into the highest modes below the critical step; equal sub-steps (5 x 0.814 dt) do not.
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  ExplicitOptions o;
  o.global_stable_step = true;
  ExplicitIntegrator run(gps, s.rho(), {}, o);
  State st = State::at_rest(*s.mesh);
  std::mt19937_64 rng(53);
  std::normal_distribution<double> n;
  for (auto& p : st.x) p += 1e-7 * Vec3(n(rng), n(rng), n(rng));
  const double tick = 4.07 * run.dt_s();
  long steps = 0;
  EXPECT_NO_THROW(for (int k = 0; k < 3000; ++k) steps += run.advance(st, tick));
  EXPECT_EQ(steps, 5 * 3000);
  EXPECT_NEAR(st.time_s, 3000 * tick, 1e-9 * 3000 * tick);
  double amplitude = 0;
  for (std::size_t i = 0; i < st.x.size(); ++i) amplitude = std::max(amplitude, (st.x[i] - s.mesh->nodes[i]).norm());
  EXPECT_LT(amplitude, 1e-6);
}

TEST(Implicit, StaticComplianceEqualsTheDenseInverseOfTheRestStiffness) {
  // The calibrated GPS equals linear FE at small strain, so its factorised rest tangent must
  // invert the dense linear-FE stiffness assembled above, fixed nodes removed.
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()}, {}, {GpsVariant::energy_consistent, 0.0});
  BoundaryConditions bc;
  const Box box = bounding_box(*s.mesh);
  bc.fixed_nodes = nodes_in_box(*s.mesh, {box.lo, Vec3(box.lo.x() + 0.2 * (box.hi.x() - box.lo.x()), box.hi.y(), box.hi.z())});
  ImplicitIntegrator implicit(gps, s.rho(), bc, {1e-3});
  ASSERT_TRUE(implicit.factorize_stiffness(s.mesh->nodes));
  const Eigen::MatrixXd K = dense_stiffness(*s.mesh, test::soft_tissue());
  std::vector<bool> fixed(s.mesh->node_count(), false);
  for (auto i : bc.fixed_nodes) fixed[static_cast<std::size_t>(i)] = true;
  std::vector<Eigen::Index> free;
  for (Eigen::Index c = 0; c < K.rows(); ++c)
    if (!fixed[static_cast<std::size_t>(c / 3)]) free.push_back(c);
  Eigen::MatrixXd Kf(free.size(), free.size());
  for (std::size_t a = 0; a < free.size(); ++a)
    for (std::size_t b = 0; b < free.size(); ++b) Kf(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = K(free[a], free[b]);
  const Eigen::LLT<Eigen::MatrixXd> llt(Kf);
  // A load at the node farthest from the fixed end, along each axis.
  std::size_t tip = 0;
  for (std::size_t i = 0; i < s.mesh->node_count(); ++i)
    if (s.mesh->nodes[i].x() > s.mesh->nodes[tip].x()) tip = i;
  std::vector<Vec3> f(s.mesh->node_count(), Vec3::Zero()), u(s.mesh->node_count());
  for (int d = 0; d < 3; ++d) {
    f[tip] = Vec3::Unit(d);
    implicit.compliance(f, u);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(free.size()));
    for (std::size_t a = 0; a < free.size(); ++a)
      if (free[a] == static_cast<Eigen::Index>(3 * tip) + d) b(static_cast<Eigen::Index>(a)) = 1.0;
    const Eigen::VectorXd ref = llt.solve(b);
    double err = 0, scale = 0;
    for (std::size_t a = 0; a < free.size(); ++a) {
      const double mine = u[static_cast<std::size_t>(free[a] / 3)][static_cast<int>(free[a] % 3)];
      err = std::max(err, std::abs(mine - ref(static_cast<Eigen::Index>(a))));
      scale = std::max(scale, std::abs(ref(static_cast<Eigen::Index>(a))));
    }
    EXPECT_LT(err, 1e-8 * scale) << "axis " << d;
    for (auto i : bc.fixed_nodes) EXPECT_EQ(u[static_cast<std::size_t>(i)].norm(), 0.0);
  }
}

// Selective mass scaling (mass_scaling.hpp) against theory: the stated mass is added, every
// element's own step reaches the threshold, the true global step then exceeds it (the element
// eigenvalue bound, Irons), weight and statics stay physical, and the lowest natural frequency
// drops exactly as far as the Rayleigh quotient of the unscaled mode allows.
