#include "viscera/tissue/model/force_model.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>

namespace viscera::tissue {

ForceModel::ForceModel(std::shared_ptr<const TetMesh> rest_mesh) : mesh_(std::move(rest_mesh)) {}

double ForceModel::element_max_edge_strain(std::span<const Vec3> x, std::size_t e) const {
  const auto p = gather(x, e);
  const auto r = gather(mesh_->nodes, e);
  double worst = 0.0;
  for (const auto& [a, b] : kTetEdges) {
    const double L0 = (r[b] - r[a]).norm();
    const double s = std::abs((p[b] - p[a]).norm() - L0) / L0;
    if (!(s <= worst)) worst = s;  // propagates NaN
  }
  return worst;
}

std::size_t find_max_strain_element(const ForceModel& model, std::span<const Vec3> x) {
  std::size_t worst = 0;
  double worst_value = -1.0;
  for (std::size_t e = 0; e < model.element_count(); ++e) {
    const double s = model.element_max_edge_strain(x, e);
    if (std::isnan(s)) return e;
    if (s > worst_value) {
      worst_value = s;
      worst = e;
    }
  }
  return worst;
}

}  // namespace viscera::tissue
