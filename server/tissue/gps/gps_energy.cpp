// The GPS's elastic energy, whole or one element's (docs/TISSUE.md): 0.5 dL^T H dL over the  // SPDX-License-Identifier: Apache-2.0
// elements, with the edge map's stiffening where it has an energy, plus the volume term; and how
// much stiffer than at rest the energy's curvature grows with the edge strain (GpsMechanisms).
#include <algorithm>
#include <cmath>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/gps/fung_map.hpp"
#include "viscera/tissue/gps/gps_model.hpp"

namespace viscera::tissue {

double GpsModel::element_energy(std::span<const Vec3> x, std::size_t e, const Tet& t) const {
  // With the edge-map stiffening that has no energy, the linear energy.
  const GpsMechanisms& mech = options_.mechanisms;
  const double qlv = mech.stiffening.b;
  const bool qlv_energy = mech.energy_map();
  const double ratio = mech.asymmetry.compression_ratio;
  const std::array<Vec3, 4> p{x[t[0]], x[t[1]], x[t[2]], x[t[3]]};
  const std::array<Vec3, 4> r{mesh_->nodes[t[0]], mesh_->nodes[t[1]], mesh_->nodes[t[2]], mesh_->nodes[t[3]]};
  Vec6 dL;
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    const Vec3 du = (p[b] - r[b]) - (p[a] - r[a]);
    const Vec3 y = p[b] - p[a];
    dL(k) = (2.0 * y - du).dot(du) / (y.norm() + edge_length(e, k));
    if (qlv_energy) dL(k) = edge_length(e, k) * edge_energy_map(qlv, ratio, dL(k) / edge_length(e, k), mech.stiffening.shape).h;
  }
  double sum = 0.5 * dL.dot(packed_hessian(e) * dL);
  if (options_.large_strain) {  // the linear edge response is the backbone's
    Vec6 raw;
    for (int k = 0; k < 6; ++k) {
      const int a = kTetEdges[k][0], b = kTetEdges[k][1];
      const Vec3 du = (p[b] - r[b]) - (p[a] - r[a]);
      raw(k) = (2.0 * (p[b] - p[a]) - du).dot(du) / ((p[b] - p[a]).norm() + edge_length(e, k));
    }
    sum += neo_hookean_energy(backbone(e), p, rest_shape_inverse(r), signed_volume(r[0], r[1], r[2], r[3])) - 0.5 * raw.dot(packed_hessian(e) * raw);
  }
  if (with_volume_) {
    const Block& b = blocks_[e / kLanes];
    const double V0 = b.rest_volume[e % kLanes];
    const double q = signed_volume(p[0], p[1], p[2], p[3]) / V0 - 1.0;
    sum += 0.5 * b.kappa[e % kLanes] * V0 * q * q;
  }
  return sum;
}

double GpsModel::energy(std::span<const Vec3> x) const {
  double sum = 0.0;
  for (std::size_t e = 0; e < element_count(); ++e) sum += element_energy(x, e, element(e));
  return sum;
}

double GpsModel::stiffness_growth(double edge_strain) const {
  const double mechanisms = options_.mechanisms.stiffness_growth(edge_strain);
  if (!options_.large_strain) return mechanisms;
  // The backbone's tangent grows with the stretches: its volumetric part lam cof (x) cof as their
  // fourth power, lam (J - alpha) d cof / dF with the volume change. Sampled over deformation
  // gradients whose singular values lie within 1 +- e (tests/tissue/large_strain_test.cpp), its
  // largest eigenvalue grew at most 1.79x at e = 0.1, 2.85x at 0.2, 6.0x at 0.4, 29x at 1: below
  // 1.05 (1 + e)^6 everywhere. The edges add their mechanisms' excess over the linear response.
  const double e = std::abs(edge_strain);
  return 1.05 * std::pow(1.0 + e, 6) + (mechanisms - 1.0);
}

double GpsMechanisms::stiffness_growth(double edge_strain) const {
  if (!stiffening.active() && !asymmetry.active()) return 1.0;
  // h h' is the edge map g in both forms, so h'^2 + h h'' = g' (the published form's tangent
  // H diag(g')); the curvature grows monotonically in |e| for every shape, so its ends bound it.
  const double b = stiffening.b, r = asymmetry.compression_ratio, e = std::abs(edge_strain);
  const auto curvature = [&](double strain) {
    const FungEnergyMap f = edge_energy_map(b, r, strain, stiffening.shape);
    return f.dh * f.dh + std::abs(f.h * f.d2h);
  };
  const double rest = edge_energy_map(b, r, 0.0, stiffening.shape).dh;
  return std::max({1.0, curvature(e) / (rest * rest), curvature(-e) / (rest * rest)});
}

}  // namespace viscera::tissue
