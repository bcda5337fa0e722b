// Integrators against theory: the computed stable step versus the true global limit 2/omega_max,
// instability detected at the limit, backward Euler against a dense solve, static equilibrium.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "common/input_error.hpp"
#include "fem/finite_element_model.hpp"
#include "gps/gps_model.hpp"
#include "integrator/explicit_integrator.hpp"
#include "integrator/implicit_integrator.hpp"
#include "mesh/box_mesh.hpp"
#include "test_support.hpp"

using namespace viscera::tissue;
namespace test = viscera::tissue::test;

namespace {

// Dense global stiffness at rest over all nodes (an independent assembly path).
Eigen::MatrixXd dense_stiffness(const TetMesh& mesh, const Mat6& D) {
  const auto n = static_cast<Eigen::Index>(3 * mesh.node_count());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  for (const Tet& t : mesh.tets) {
    const Mat12 Ke = linear_fe_stiffness({mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]}, D);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) K.block<3, 3>(3 * t[a], 3 * t[b]) += Ke.block<3, 3>(3 * a, 3 * b);
  }
  return K;
}

struct Fixture {
  std::shared_ptr<TetMesh> mesh = std::make_shared<TetMesh>(read_tet_mesh(test::data_path("meshes/liver.msh")));
  Fixture() { scale_mesh(*mesh, 0.035); }
  std::vector<double> rho() const { return std::vector<double>(mesh->tet_count(), 1060.0); }
};

double true_critical_step(const TetMesh& mesh, const std::vector<double>& masses, const Mat6& D) {
  const Eigen::MatrixXd K = dense_stiffness(mesh, D);
  Eigen::VectorXd inv_sqrt_m(K.rows());
  for (Eigen::Index i = 0; i < K.rows(); ++i) inv_sqrt_m(i) = 1.0 / std::sqrt(masses[static_cast<std::size_t>(i / 3)]);
  const Eigen::MatrixXd A = inv_sqrt_m.asDiagonal() * K * inv_sqrt_m.asDiagonal();
  const double omega2 = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  return 2.0 / std::sqrt(omega2);
}

}  // namespace

TEST(StableStep, IsSafeAndNotFarFromTheTrueGlobalLimit) {
  Fixture s;
  const GpsModel gps(s.mesh, {test::soft_tissue()});
  const ExplicitIntegrator integrator(gps, s.rho(), {});
  const double exact = true_critical_step(*s.mesh, integrator.masses(), test::soft_tissue());
  const double computed = integrator.critical_step().dt_s;
  std::cout << "[ figure ] liver (596 tets): element-bound critical step " << computed << " s, true global "
            << exact << " s, ratio " << computed / exact << "\n";
  EXPECT_LE(computed, exact * (1 + 1e-9));
  EXPECT_GT(computed, 0.2 * exact);  // the element bound is conservative (Irons)
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
  std::cout << "[ figure ] static sag of a cantilevered liver under gravity: " << sag << " m in "
            << rep.iterations << " Newton iterations, residual " << rep.residual_n << " N of " << rep.force_scale_n
            << " N\n";
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
  std::cout << "[ figure ] liver (596 tets): global estimate of the critical step " << estimate << " s, true " << exact
            << " s, ratio " << estimate / exact << "\n";
  EXPECT_LE(estimate, exact);         // the margin covers the Rayleigh quotient's underestimate
  EXPECT_GT(estimate, 0.9 * exact);   // and costs little
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
    return [&, report](std::span<const Vec3> x, std::span<Vec3> f, std::span<double> stiffness) {
      for (std::size_t i = 0; i < x.size(); ++i) {
        f[i] += k * (rest[i] - x[i]);
        if (report) stiffness[i] += k;
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
