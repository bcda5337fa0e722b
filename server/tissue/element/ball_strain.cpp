#include "viscera/tissue/element/ball_strain.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace viscera::tissue {

double principal_stretch_strain(const Mat3& green) {
  // The largest and smallest eigenvalues in closed form (the trigonometric solution of the
  // characteristic cubic): with Eigen's computeDirect instead, the average over a ball took 163 ns
  // a tetrahedron against 110 ns. The largest departure of a stretch from 1 is at one of the two.
  const Mat3& E = green;
  const double q = E.trace() / 3.0;
  const double off = E(0, 1) * E(0, 1) + E(0, 2) * E(0, 2) + E(1, 2) * E(1, 2);
  const double p2 = (E(0, 0) - q) * (E(0, 0) - q) + (E(1, 1) - q) * (E(1, 1) - q) + (E(2, 2) - q) * (E(2, 2) - q) + 2.0 * off;
  double largest = q, smallest = q;
  if (p2 > 0.0) {
    // The eigenvalues are q + 2p cos(phi + 2 pi k / 3), phi = acos(det((E - q I) / p) / 2) / 3.
    const double p = std::sqrt(p2 / 6.0);
    const Mat3 B = E - q * Mat3::Identity();
    const double r = std::clamp(0.5 * B.determinant() / (p * p * p), -1.0, 1.0);
    const double c = std::cos(std::acos(r) / 3.0), s = std::sqrt(std::max(0.0, 1.0 - c * c));
    largest = q + 2.0 * p * c;
    smallest = q - p * (c + std::numbers::sqrt3 * s);  // 2p cos(phi + 2 pi / 3)
  }
  double worst = 0.0;
  for (const double e : {largest, smallest}) {
    // sqrt(1 + 2e) - 1 without the cancellation at small e.
    const double s = 1.0 + 2.0 * e <= 0.0 ? -1.0 : 2.0 * e / (std::sqrt(1.0 + 2.0 * e) + 1.0);
    if (!(std::abs(s) <= worst)) worst = std::abs(s);  // propagates NaN
  }
  return worst;
}

namespace {

std::array<Vec3, 4> corners(const TetMesh& mesh, std::size_t e) {
  const Tet& t = mesh.tets[e];
  return {mesh.nodes[static_cast<std::size_t>(t[0])], mesh.nodes[static_cast<std::size_t>(t[1])], mesh.nodes[static_cast<std::size_t>(t[2])],
          mesh.nodes[static_cast<std::size_t>(t[3])]};
}

Mat3 green_from(const TetMesh& rest, std::span<const Vec3> x, std::size_t e, const Mat3& dm_inv) {
  const Tet& t = rest.tets[e];
  const auto u = [&](int k) { return Vec3(x[static_cast<std::size_t>(t[k])] - rest.nodes[static_cast<std::size_t>(t[k])]); };
  const Vec3 u0 = u(0);
  Mat3 du;
  du.col(0) = u(1) - u0;
  du.col(1) = u(2) - u0;
  du.col(2) = u(3) - u0;
  const Mat3 g = du * dm_inv;
  return 0.5 * (g + g.transpose() + g.transpose() * g);
}

}  // namespace

BallStrain::BallStrain(std::shared_ptr<const TetMesh> rest, double radius_m) : rest_(std::move(rest)), radius_(radius_m) {
  if (!rest_ || rest_->tets.empty()) throw std::invalid_argument("BallStrain: no mesh");
  if (!(radius_m > 0 && std::isfinite(radius_m))) throw std::invalid_argument("BallStrain: the radius must be positive");
  const std::size_t n = rest_->tets.size();
  for (std::size_t e = 0; e < n; ++e) describe(e);
  moved_.assign(n, 0);
  Vec3 lo = centroid_[0], hi = centroid_[0];
  for (const Vec3& c : centroid_) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  // Cells of the radius, but at most 128 along the longest side (a tiny radius on a large organ).
  cell_ = std::max(radius_, (hi - lo).maxCoeff() / 128.0);
  if (!(cell_ > 0)) cell_ = radius_;
  origin_ = lo;
  for (int k = 0; k < 3; ++k) dims_[static_cast<std::size_t>(k)] = static_cast<int>(std::floor((hi[k] - lo[k]) / cell_)) + 1;
  const auto cell_of = [&](const Vec3& c) {
    std::size_t index = 0;
    for (int k = 2; k >= 0; --k) {
      const int i = std::clamp(static_cast<int>(std::floor((c[k] - origin_[k]) / cell_)), 0, dims_[static_cast<std::size_t>(k)] - 1);
      index = index * static_cast<std::size_t>(dims_[static_cast<std::size_t>(k)]) + static_cast<std::size_t>(i);
    }
    return index;
  };
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * static_cast<std::size_t>(dims_[1]) * static_cast<std::size_t>(dims_[2]);
  grid_start_.assign(cells + 1, 0);
  for (const Vec3& c : centroid_) ++grid_start_[cell_of(c) + 1];
  for (std::size_t c = 0; c < cells; ++c) grid_start_[c + 1] += grid_start_[c];
  grid_elements_.resize(n);
  std::vector<std::uint32_t> fill(grid_start_.begin(), grid_start_.end() - 1);
  for (std::size_t e = 0; e < n; ++e) grid_elements_[fill[cell_of(centroid_[e])]++] = static_cast<std::uint32_t>(e);
}

void BallStrain::describe(std::size_t e) {
  const auto r = corners(*rest_, e);
  if (dm_inv_.size() <= e) {
    dm_inv_.resize(e + 1);
    volume_.resize(e + 1);
    centroid_.resize(e + 1);
  }
  dm_inv_[e] = edge_matrix(r).inverse();
  volume_[e] = std::abs(signed_volume(r[0], r[1], r[2], r[3]));
  centroid_[e] = 0.25 * (r[0] + r[1] + r[2] + r[3]);
}

void BallStrain::follow_edit(const MeshEdit& edit) {
  const std::size_t n = rest_->tets.size();
  moved_.resize(n, 1);
  for (const auto& [e, before] : edit.replaced) {
    const auto i = static_cast<std::size_t>(e);
    describe(i);
    if (!moved_[i]) {
      moved_[i] = 1;
      loose_.push_back(static_cast<std::uint32_t>(i));
    }
  }
  for (std::size_t e = edit.elements_before; e < n; ++e) {
    describe(e);
    loose_.push_back(static_cast<std::uint32_t>(e));
  }
}

template <class Visit>
void BallStrain::visit_near(const Vec3& p, Visit&& visit) const {
  const double r2 = radius_ * radius_;
  std::array<int, 3> from{}, to{};
  for (int k = 0; k < 3; ++k) {
    const auto d = static_cast<std::size_t>(k);
    from[d] = std::max(0, static_cast<int>(std::floor((p[k] - radius_ - origin_[k]) / cell_)));
    to[d] = std::min(dims_[d] - 1, static_cast<int>(std::floor((p[k] + radius_ - origin_[k]) / cell_)));
  }
  for (int z = from[2]; z <= to[2]; ++z)
    for (int y = from[1]; y <= to[1]; ++y)
      for (int x = from[0]; x <= to[0]; ++x) {
        const std::size_t c =
            (static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_[1]) + static_cast<std::size_t>(y)) * static_cast<std::size_t>(dims_[0]) +
            static_cast<std::size_t>(x);
        for (std::uint32_t k = grid_start_[c]; k < grid_start_[c + 1]; ++k) {
          const std::uint32_t e = grid_elements_[k];
          if (!moved_[e] && (centroid_[e] - p).squaredNorm() <= r2) visit(static_cast<std::size_t>(e));
        }
      }
  for (const std::uint32_t e : loose_)
    if ((centroid_[e] - p).squaredNorm() <= r2) visit(static_cast<std::size_t>(e));
}

void BallStrain::elements_near(const Vec3& rest_point, std::vector<std::size_t>& found) const {
  found.clear();
  visit_near(rest_point, [&](std::size_t e) { found.push_back(e); });
  if (found.empty()) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t nearest = 0;
    for (std::size_t e = 0; e < centroid_.size(); ++e)
      if (const double d = (centroid_[e] - rest_point).squaredNorm(); d < best) {
        best = d;
        nearest = e;
      }
    found.push_back(nearest);
  }
  std::sort(found.begin(), found.end());
}

BallStrain::Sum BallStrain::sum_over(std::span<const Vec3> x, std::span<const std::size_t> elements, std::size_t first, std::size_t stride) const {
  Sum s;
  for (std::size_t k = first; k < elements.size(); k += std::max<std::size_t>(stride, 1)) {
    const std::size_t e = elements[k];
    s.strain_volume_m3 += volume_[e] * principal_stretch_strain(green_from(*rest_, x, e, dm_inv_[e]));
    s.volume_m3 += volume_[e];
  }
  return s;
}

BallStrain::Result BallStrain::at(std::span<const Vec3> x, const Vec3& rest_point) const {
  Result r;
  const auto add = [&](std::size_t e) {
    r.strain += volume_[e] * principal_stretch_strain(green_from(*rest_, x, e, dm_inv_[e]));
    r.volume_m3 += volume_[e];
    ++r.elements;
  };
  visit_near(rest_point, add);
  if (r.elements == 0) {
    std::vector<std::size_t> nearest;
    elements_near(rest_point, nearest);
    add(nearest.front());
  }
  r.strain /= r.volume_m3;
  return r;
}

}  // namespace viscera::tissue
