// The tissue's strain averaged over a ball (tissue/element/ball_strain.hpp), against closed forms:  // SPDX-License-Identifier: Apache-2.0
// a uniform deformation, whose strain every mesh must give exactly; the ball's elements against a
// search over all of them; a smooth local dent against the ball average of its analytic strain,
// computed by quadrature, on three meshes of a box.
#include "viscera/tissue/element/ball_strain.hpp"

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/refinement.hpp"

#include "test_support.hpp"

namespace viscera::tissue {
namespace {

std::vector<std::size_t> near(const BallStrain& ball, const Vec3& p) {
  std::vector<std::size_t> out;
  ball.elements_near(p, out);
  return out;
}

std::vector<std::size_t> brute_force_ball(const TetMesh& m, const Vec3& p, double r) {
  std::vector<std::size_t> in;
  double best = 1e300;
  std::size_t nearest = 0;
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    Vec3 c = Vec3::Zero();
    for (const auto v : m.tets[e]) c += 0.25 * m.nodes[static_cast<std::size_t>(v)];
    const double d = (c - p).norm();
    if (d <= r) in.push_back(e);
    if (d < best) {
      best = d;
      nearest = e;
    }
  }
  if (in.empty()) in.push_back(nearest);
  return in;
}

TEST(BallStrain, AUniformDeformationGivesItsPrincipalStrainOnEveryMesh) {
  std::mt19937_64 rng(7);
  auto coarse = test::liver2();
  auto fine = std::make_shared<TetMesh>(refine_uniform(*coarse));
  auto box = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.05, 0.03, 0.02), 10, 6, 4));
  // Principal stretches 1.3, 0.85 and 1.05 in a random frame, then a rotation and a shift.
  const Mat3 Q = test::random_rotation(rng), R = test::random_rotation(rng);
  const Mat3 F = R * Q * Vec3(1.3, 0.85, 1.05).asDiagonal() * Q.transpose();
  EXPECT_NEAR(principal_stretch_strain(0.5 * (F.transpose() * F - Mat3::Identity())), 0.3, 1e-14);
  for (const auto& mesh : {coarse, fine, box}) {
    std::vector<Vec3> x;
    for (const Vec3& X : mesh->nodes) x.push_back(F * X + Vec3(0.1, -0.2, 0.3));
    for (const double radius : {0.002, 0.01, 0.04}) {
      const BallStrain ball(mesh, radius);
      for (int k = 0; k < 20; ++k) {
        const Vec3 p = mesh->nodes[rng() % mesh->nodes.size()];
        const auto r = ball.at(x, p);
        EXPECT_NEAR(r.strain, 0.3, 1e-12) << mesh->source << " radius " << radius;
        EXPECT_GE(r.elements, 1u);
        // The ball spread over three shares gives the same average.
        const auto elements = near(ball, p);
        double sv = 0, v = 0;
        for (std::size_t first = 0; first < 3; ++first) {
          const auto s = ball.sum_over(x, elements, first, 3);
          sv += s.strain_volume_m3;
          v += s.volume_m3;
        }
        EXPECT_NEAR(sv / v, 0.3, 1e-12);
        EXPECT_NEAR(v, r.volume_m3, 1e-15);
      }
    }
  }
}

TEST(BallStrain, SmallStrainsKeepTheirDigitsUnderARotation) {
  std::mt19937_64 rng(3);
  auto mesh = test::liver2();
  const Mat3 R = test::random_rotation(rng);
  // 1e-8 along x, rotated by a finite angle: E = (F^T F - I) / 2 from positions would lose it.
  const Mat3 F = R * Vec3(1 + 1e-8, 1, 1).asDiagonal();
  std::vector<Vec3> x;
  for (const Vec3& X : mesh->nodes) x.push_back(F * X);
  const BallStrain ball(mesh, 0.01);
  const auto r = ball.at(x, mesh->nodes[10]);
  EXPECT_NEAR(r.strain, 1e-8, 1e-13);
  EXPECT_NEAR(principal_stretch_strain(Vec3(-0.18, 0.0, 0.0).asDiagonal()), 1 - std::sqrt(1 - 0.36), 1e-15);  // compression: 1 - 0.8
}

TEST(BallStrain, TheBallHoldsTheElementsWhoseCentroidsLieWithinItsRadius) {
  std::mt19937_64 rng(11);
  auto mesh = test::liver2();
  std::uniform_real_distribution<double> u(-0.12, 0.12);
  for (const double radius : {0.0005, 0.005, 0.01, 0.03, 0.3}) {
    const BallStrain ball(mesh, radius);
    for (int k = 0; k < 200; ++k) {
      // Nodes, and points anywhere around the organ (outside: the nearest element).
      const Vec3 p = k % 2 ? mesh->nodes[rng() % mesh->nodes.size()] : Vec3(u(rng), u(rng), u(rng));
      EXPECT_EQ(near(ball, p), brute_force_ball(*mesh, p, radius)) << "radius " << radius;
    }
  }
}

TEST(BallStrain, FollowsTheElementsAnEditChangedOrAdded) {
  std::mt19937_64 rng(5);
  auto mesh = std::make_shared<TetMesh>(*test::liver2());
  const BallStrain before(mesh, 0.01);
  BallStrain ball(mesh, 0.01);
  // An edit as a cut makes one: some elements get other vertices (one of them a new node), and
  // new elements are appended.
  const std::size_t nodes_before = mesh->nodes.size(), elements_before = mesh->tets.size();
  mesh->nodes.push_back(0.5 * (mesh->nodes[0] + mesh->nodes[1]));
  std::vector<std::pair<std::int32_t, Tet>> replaced;
  std::vector<std::int32_t> origin(elements_before);
  for (std::size_t e = 0; e < elements_before; ++e) origin[e] = static_cast<std::int32_t>(e);
  for (const std::size_t e : {3u, 400u, 1200u}) {
    replaced.push_back({static_cast<std::int32_t>(e), mesh->tets[e]});
    mesh->tets[e] = mesh->tets[(e * 7 + 11) % elements_before];
    mesh->tets[e][0] = static_cast<std::int32_t>(nodes_before);
  }
  for (int k = 0; k < 5; ++k) {
    mesh->tets.push_back(mesh->tets[rng() % elements_before]);
    origin.push_back(static_cast<std::int32_t>(k));
  }
  const std::vector<MeshEdit::NewNode> new_nodes{{0, 1, 0.5}};
  ball.follow_edit({nodes_before, elements_before, new_nodes, origin, replaced});
  int differ = 0;
  for (std::size_t k = 0; k < 300; ++k) {
    const Vec3 p = mesh->nodes[rng() % mesh->nodes.size()];
    const auto now = near(ball, p);
    EXPECT_EQ(now, brute_force_ball(*mesh, p, 0.01));
    differ += now != near(before, p);  // the ball that did not follow the edit
  }
  EXPECT_GT(differ, 0);
}

// A dent of depth a and width w at X0 on the top of a box: u = -a exp(-|X - X0|^2 / w^2) e_z.
struct Dent {
  Vec3 X0;
  double a, w;
  Vec3 u(const Vec3& X) const { return Vec3(0, 0, -a * std::exp(-(X - X0).squaredNorm() / (w * w))); }
  Mat3 green(const Vec3& X) const {
    Mat3 g = Mat3::Zero();  // du_z / dX
    g.row(2) = (2.0 * a / (w * w)) * std::exp(-(X - X0).squaredNorm() / (w * w)) * (X - X0).transpose();
    return 0.5 * (g + g.transpose() + g.transpose() * g);
  }
};

TEST(BallStrain, ConvergesToTheBallAverageOfTheStrainAsTheMeshIsRefined) {
  const Vec3 lo(0, 0, 0), hi(0.06, 0.06, 0.03);
  const Dent dent{Vec3(0.03, 0.03, 0.015), 0.004, 0.01};
  const double radius = 0.01;
  // The reference: the analytic strain averaged over the ball by the midpoint rule on 100^3 cells.
  double sum = 0.0;
  double count = 0;
  const int q = 100;
  for (int i = 0; i < q; ++i)
    for (int j = 0; j < q; ++j)
      for (int k = 0; k < q; ++k) {
        const Vec3 d = radius * (Vec3(i + 0.5, j + 0.5, k + 0.5) * (2.0 / q) - Vec3::Ones());
        if (d.norm() > radius) continue;
        sum += principal_stretch_strain(dent.green(dent.X0 + d));
        count += 1;
      }
  const double reference = sum / count;
  // Averaged as a tensor, the strain's turning sign about the centre would cancel.
  Mat3 tensor = Mat3::Zero();
  for (int k = 0; k < 1000; ++k) tensor += dent.green(dent.X0 + radius * Vec3(std::cos(k), std::sin(1.7 * k), std::cos(2.3 * k)) / std::sqrt(3.0));
  double peak = 0.0;  // the largest pointwise strain, for scale
  for (int k = 1; k < 100; ++k)
    for (int axis = 0; axis < 3; ++axis) peak = std::max(peak, principal_stretch_strain(dent.green(dent.X0 + k * 1e-4 * Vec3::Unit(axis))));
  ASSERT_GT(peak, reference);
  ASSERT_LT(principal_stretch_strain(tensor / 1000), 0.5 * reference);
  std::vector<double> error;
  for (const int n : {6, 12, 24}) {  // cells of 10, 5 and 2.5 mm
    auto mesh = std::make_shared<TetMesh>(make_box_mesh(lo, hi, n, n, n / 2));
    std::vector<Vec3> x;
    for (const Vec3& X : mesh->nodes) x.push_back(X + dent.u(X));
    const BallStrain ball(mesh, radius);
    error.push_back(std::abs(ball.at(x, dent.X0).strain - reference) / reference);
  }
  EXPECT_LT(error[2], error[0]);
  EXPECT_LT(error[2], 0.05) << "errors " << error[0] << ", " << error[1] << ", " << error[2];
  RecordProperty("relative_errors", std::to_string(error[0]) + " " + std::to_string(error[1]) + " " + std::to_string(error[2]));
  std::printf("ball average %.4f (peak %.4f); relative errors on 10, 5, 2.5 mm cells: %.4f %.4f %.4f\n", reference, peak, error[0], error[1],
              error[2]);
}

// The closed form of the extreme eigenvalues against an eigensolver, on random strains of every
// size, and on the degenerate ones (equal eigenvalues, diagonal).
TEST(BallStrain, ThePrincipalStrainEqualsAnEigensolversOnRandomAndDegenerateStrains) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto reference = [](const Mat3& E) {
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(E, Eigen::EigenvaluesOnly);
    double worst = 0.0;
    for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(std::sqrt(std::max(0.0, 1.0 + 2.0 * eig.eigenvalues()(i))) - 1.0));
    return worst;
  };
  for (int k = 0; k < 2000; ++k) {
    const double scale = std::pow(10.0, -6.0 + 5.5 * (k % 100) / 100.0);  // 1e-6 to 0.3
    Mat3 A;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) A(i, j) = u(rng);
    const Mat3 E = scale * 0.5 * (A + A.transpose());
    EXPECT_NEAR(principal_stretch_strain(E), reference(E), 1e-9 * scale) << "scale " << scale;
  }
  const Mat3 R = test::random_rotation(rng);
  for (const Vec3& d : {Vec3(0.1, 0.1, 0.1), Vec3(0.2, 0.2, -0.1), Vec3(0.0, 0.0, 0.0), Vec3(-0.3, 0.05, 0.05)}) {
    const Mat3 E = R * d.asDiagonal() * R.transpose();
    EXPECT_NEAR(principal_stretch_strain(E), reference(E), 1e-8) << d.transpose();  // acos near +-1: sqrt(eps)
    EXPECT_NEAR(principal_stretch_strain(Mat3(d.asDiagonal())), reference(Mat3(d.asDiagonal())), 1e-8);
  }
}

}  // namespace
}  // namespace viscera::tissue
