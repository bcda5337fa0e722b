#pragma once  // SPDX-License-Identifier: Apache-2.0
// Helpers shared by the tissue tests: random well-shaped tetrahedra, the bundled organ meshes.
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/mesh_validation.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue::test {

inline std::string data_path(const std::string& rel) { return std::string(VISCERA_DATA_DIR) + "/" + rel; }

inline std::string tmp_path(const std::string& name) {
  std::filesystem::create_directories(VISCERA_TEST_TMP);
  return std::string(VISCERA_TEST_TMP) + "/" + name;
}

inline std::string write_file(const std::string& name, const std::string& text) {
  const std::string p = tmp_path(name);
  std::ofstream(p) << text;
  return p;
}

/// liver2.msh scaled to about 17 cm across (0.08 m per mesh unit).
inline constexpr double kLiverScale = 0.08;
inline std::shared_ptr<TetMesh> liver2() {
  auto m = std::make_shared<TetMesh>(read_tet_mesh(data_path("meshes/liver2.msh")));
  scale_mesh(*m, kLiverScale);
  return m;
}

/// A random tetrahedron of about `size` metres with shape quality >= min_quality, positive.
inline std::array<Vec3, 4> random_tet(std::mt19937_64& rng, double size = 0.01, double min_quality = 0.3) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    std::array<Vec3, 4> x;
    for (auto& p : x) p = size * Vec3(u(rng), u(rng), u(rng));
    double q = tet_quality(x[0], x[1], x[2], x[3]);
    if (q < 0) {
      std::swap(x[2], x[3]);
      q = -q;
    }
    if (q >= min_quality) return x;
  }
}

inline std::shared_ptr<TetMesh> single_tet_mesh(const std::array<Vec3, 4>& x) {
  auto m = std::make_shared<TetMesh>();
  m->nodes.assign(x.begin(), x.end());
  m->tets.push_back({0, 1, 2, 3});
  m->source = "single tet";
  return m;
}

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

/// A random symmetric positive definite elasticity matrix around `scale` pascals.
inline Mat6 random_spd(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat6 A;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = u(rng);
  return scale * (A * A.transpose() + Mat6::Identity());
}

inline Mat6 soft_tissue() { return elasticity_matrix(IsotropicElasticity{5e3, 0.45}); }

}  // namespace viscera::tissue::test
