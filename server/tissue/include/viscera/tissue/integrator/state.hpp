#pragma once  // SPDX-License-Identifier: Apache-2.0
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Positions [m], velocities [m/s] and time [s] of a simulation.
struct State {
  std::vector<Vec3> x;
  std::vector<Vec3> v;
  double time_s = 0.0;
  std::vector<double> memory;  ///< the model's memory variables (ForceModel::memory_size)
  double memory_time_s = 0.0;  ///< time of the evaluation the memory belongs to

  /// The rest state of a mesh: x = rest positions, v = 0, t = 0.
  static State at_rest(const TetMesh& mesh) { return {mesh.nodes, std::vector<Vec3>(mesh.nodes.size(), Vec3::Zero()), 0.0, {}, 0.0}; }
};

}  // namespace viscera::tissue
