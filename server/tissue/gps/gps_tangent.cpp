// The GPS's element tangent (docs/TISSUE.md): -df/dx of one element, elastic or over a  // SPDX-License-Identifier: Apache-2.0
// viscoelastic step of dt (the memory variables' relaxed share, first-load softening from the
// memory's extremes), with the edge map's stiffening and the volume term; the implicit integrator
// and the contact compliance assemble it.
#include <cmath>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/gps/fung_map.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"

namespace viscera::tissue {

Mat12 GpsModel::element_tangent(std::span<const Vec3> x, std::size_t e) const { return tangent(x, e, 1.0, 0.0); }

Mat12 GpsModel::element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s) const { return element_tangent(x, e, dt_s, {}); }

Mat12 GpsModel::element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s, std::span<const double> memory) const {
  // d(relaxed elongation)/d(dL) over a step of dt: 1 - sum Y_l c_l (+ tau / dt for Kelvin-Voigt).
  const GpsMechanisms& mech = options_.mechanisms;
  if (!mech.has_memory()) return tangent(x, e, 1.0, 0.0);
  const GpsViscous& viscous = mech.viscous;
  double shear = 1.0, bulk = 1.0;
  for (std::size_t l = 0; l < mechanisms_; ++l) {
    const double c = dt_s > 0 ? MemoryStep::make(viscous.omega_rad_s[l], dt_s).c : 0.0;
    shear -= viscous.shear_weight[l] * c;
    bulk -= viscous.bulk(l) * c;
  }
  const double kv = dt_s > 0 ? viscous.kelvin_voigt_time_s / dt_s : 0.0;
  if (options_.large_strain) return backbone_tangent(x, e, dt_s, shear + kv, memory);
  const double d = mech.softening.d;
  if (memory.size() != memory_size()) return tangent(x, e, shear + kv, bulk - shear);
  // What the step's start holds (add_forces_impl's memory update, its part that does not depend
  // on x): the relaxed elongation (or, in the energy form, tension) is
  // (shear + kv) a + sum_l y_s,l (-(e_l zeta_l + (a_l - c_l) a_prev)) - kv a_prev, and the bulk part
  // adds s hv hv . sum_l (y_s,l - y_b,l) (e_l zeta_l + (a_l - c_l) a_prev). Without it the
  // geometric stiffness took (shear + kv) times the tension: under a long Kelvin-Voigt time that
  // is thousands of times the tension, and Newton's steps stopped descending.
  const double* in = memory.data() + (e / kLanes) * memory_stride();
  const std::size_t j = e % kLanes;
  Vec6 held_a = Vec6::Zero(), held_b = Vec6::Zero();
  for (int k = 0; k < 6; ++k) {
    const double prev = in[k * kLanes + j];
    held_a(k) = -kv * prev;
    for (std::size_t l = 0; l < mechanisms_; ++l) {
      const MemoryStep st = MemoryStep::make(viscous.omega_rad_s[l], dt_s);
      const double z = st.e * in[((1 + l) * 6 + static_cast<std::size_t>(k)) * kLanes + j] + (st.a - st.c) * prev;
      held_a(k) -= viscous.shear_weight[l] * z;
      held_b(k) += (viscous.shear_weight[l] - viscous.bulk(l)) * z;
    }
  }
  Vec6 held = options_.mechanisms.energy_map() ? held_a : Vec6(packed_hessian(e) * held_a);
  if (!bulk_.empty()) {
    const BulkBlock& bb = bulk_[e / kLanes];
    Vec6 hv;
    for (int k = 0; k < 6; ++k) hv(k) = bb.hv[k][j];
    held += bb.scale[j] * hv * hv.dot(held_b);
  }
  if (!(d > 0)) return tangent(x, e, shear + kv, bulk - shear, nullptr, nullptr, &held);
  // First-load softening: the factors at x for the extremes the step started with.
  const auto p = gather(x, e);
  const double* peaks = in + softening_offset();
  Vec6 phi = Vec6::Ones(), dphi = Vec6::Zero();
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    const double strain = ((p[b] - p[a]).norm() - edge_length(e, k)) / edge_length(e, k);
    const double peak = strain >= 0 ? peaks[k * kLanes + j] : peaks[(6 + k) * kLanes + j];
    if (std::abs(strain) < peak) {
      phi(k) = 1.0 - d * (1.0 - std::abs(strain) / peak);
      dphi(k) = d * (strain >= 0 ? 1.0 : -1.0) / peak;
    }
  }
  return tangent(x, e, shear + kv, bulk - shear, &phi, &dphi, &held);
}

Mat12 GpsModel::backbone_tangent(std::span<const Vec3> x, std::size_t e, double dt_s, double scale, std::span<const double> memory) const {
  // The large-strain GPS with memory (its edges idle: no stiffening): P = P_e(F) + kappa F q(F)
  // - F H, kappa = scale - 1 = tau / dt - sum_l y_l c_l, q the filtered stress (S, for which
  // F S = P_e, or DEV[S]), H = sum_l y_l (e_l zeta_l + (a_l - c_l) q_prev) + (tau / dt) q_prev:
  // what the step's start holds.
  const auto p = gather(x, e), rest = gather(mesh_->nodes, e);
  const Mat3 dm_inv = rest_shape_inverse(rest);
  const double V0 = signed_volume(rest[0], rest[1], rest[2], rest[3]);
  Mat12 K = deviatoric_memory_
                ? Mat12(neo_hookean_tangent(backbone(e), p, dm_inv, V0) + (scale - 1.0) * deviatoric_stress_tangent(backbone(e), p, dm_inv, V0))
                : Mat12(scale * neo_hookean_tangent(backbone(e), p, dm_inv, V0));
  if (memory.size() != memory_size()) return K;
  const GpsViscous& viscous = options_.mechanisms.viscous;
  const double* in = memory.data() + (e / kLanes) * memory_stride();
  const std::size_t j = e % kLanes;
  Mat3 held = Mat3::Zero();
  for (int q = 0; q < 6; ++q) {
    const double prev = in[static_cast<std::size_t>(q) * kLanes + j];
    double h = dt_s > 0 ? viscous.kelvin_voigt_time_s / dt_s * prev : 0.0;
    for (std::size_t l = 0; l < mechanisms_; ++l) {
      const MemoryStep st = MemoryStep::make(viscous.omega_rad_s[l], dt_s);
      h += viscous.shear_weight[l] * (st.e * in[((1 + l) * 6 + static_cast<std::size_t>(q)) * kLanes + j] + (st.a - st.c) * prev);
    }
    held(kVoigtPairs[q][0], kVoigtPairs[q][1]) = held(kVoigtPairs[q][1], kVoigtPairs[q][0]) = h;
  }
  return K + held_stress_tangent(held, dm_inv, V0);
}

Mat12 GpsModel::tangent(std::span<const Vec3> x, std::size_t e, double stiffness_scale, double bulk_extra, const Vec6* phi, const Vec6* dphi_de,
                        const Vec6* held) const {
  // f = P t with P_e = (+Y_e at a, -Y_e at b), t = S h, h = H dL, dL = G dx,
  // G_e = (-y_e at a, +y_e at b), y_e = Y_e / L_e. K = -df/dx (see docs/MODEL.md section 1).
  const auto p = gather(x, e);
  Mat6 H = stiffness_scale * packed_hessian(e);
  if (bulk_extra != 0.0 && !bulk_.empty()) {
    const BulkBlock& bb = bulk_[e / kLanes];
    Vec6 hv;
    for (int k = 0; k < 6; ++k) hv(k) = bb.hv[k][e % kLanes];
    H += bulk_extra * bb.scale[e % kLanes] * hv * hv.transpose();
  }
  const double qlv = options_.mechanisms.stiffening.b;
  Mat6x12 G = Mat6x12::Zero();
  Vec6 len, dL;
  Eigen::Matrix<double, 3, 6> Y;
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    Y.col(k) = p[b] - p[a];
    len(k) = Y.col(k).norm();
    dL(k) = len(k) - edge_length(e, k);
    G.block<1, 3>(k, 3 * a) = -Y.col(k).transpose() / len(k);
    G.block<1, 3>(k, 3 * b) = Y.col(k).transpose() / len(k);
  }
  Mat6x12 Gm = G;  // derivative of the (possibly QLV-mapped) elongation measure
  const bool qlv_energy = options_.mechanisms.energy_map();
  Vec6 dh = Vec6::Ones(), d2h = Vec6::Zero();  // energy form: t_k = h'_k (H h)_k
  if (qlv > 0 || qlv_energy)
    for (int k = 0; k < 6; ++k) {
      const double strain = dL(k) / edge_length(e, k);
      if (qlv_energy) {
        const FungEnergyMap m = edge_energy_map(qlv, options_.mechanisms.asymmetry.compression_ratio, strain, options_.mechanisms.stiffening.shape);
        dh(k) = m.dh;
        d2h(k) = m.d2h / edge_length(e, k);  // d h'/d dL
        Gm.row(k) *= m.dh;
        dL(k) = edge_length(e, k) * m.h;
      } else {
        Gm.row(k) *= std::exp(qlv * strain);
        dL(k) = edge_length(e, k) * std::expm1(qlv * strain) / qlv;
      }
    }
  // First-load softening scales each edge's response by phi(e): the mapped elongation (edge map)
  // or the elastic tension (energy form); d phi / dx = phi'(e) G / L0.
  const bool softened = phi != nullptr && !qlv_energy;
  if (softened)
    for (int k = 0; k < 6; ++k) {
      Gm.row(k) = (*phi)(k)*Gm.row(k) + dL(k) * (*dphi_de)(k) / edge_length(e, k) * G.row(k);
      dL(k) *= (*phi)(k);
    }
  const Vec6 Hh = H * dL;
  Vec6 h = dh.cwiseProduct(Hh);
  Vec6 soft = Vec6::Ones(), dsoft = Vec6::Zero();  // energy form: t_k = phi_k h'_k (H h)_k
  if (phi != nullptr && qlv_energy) {
    soft = *phi;
    for (int k = 0; k < 6; ++k) dsoft(k) = (*dphi_de)(k) / edge_length(e, k);
    h = h.cwiseProduct(soft);
  }
  const bool ec = options_.variant == GpsVariant::energy_consistent;
  Mat12 K = Mat12::Zero();
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    const double s = ec ? 1.0 / len(k) : 1.0 / edge_length(e, k);
    const double tension = h(k) + (held ? (*held)(k) : 0.0);
    const double tk = s * tension;
    // Material part: -P_k dt_k/dx with dt_k/dx = s (H G)_k [- h_k / L_k^2 G_k for EC].
    Eigen::Matrix<double, 1, 12> dt = s * soft(k) * dh(k) * (H.row(k) * Gm);
    if (qlv_energy) dt += s * soft(k) * d2h(k) * Hh(k) * G.row(k) + s * dsoft(k) * dh(k) * Hh(k) * G.row(k);
    if (ec) dt -= tension / (len(k) * len(k)) * G.row(k);
    K.block<3, 12>(3 * a, 0) -= Y.col(k) * dt;
    K.block<3, 12>(3 * b, 0) += Y.col(k) * dt;
    // Geometric part: -t_k dP_k/dx, dP_k/dx = [[-I, I], [I, -I]] on (a, b).
    const Mat3 I = tk * Mat3::Identity();
    K.block<3, 3>(3 * a, 3 * a) += I;
    K.block<3, 3>(3 * a, 3 * b) -= I;
    K.block<3, 3>(3 * b, 3 * a) -= I;
    K.block<3, 3>(3 * b, 3 * b) += I;
  }
  if (with_volume_) {
    const Block& bl = blocks_[e / kLanes];
    const double kappa = bl.kappa[e % kLanes], V0 = bl.rest_volume[e % kLanes];
    const Vec12 g = volume_gradient(p);
    const double V = signed_volume(p[0], p[1], p[2], p[3]);
    K += (kappa / V0) * g * g.transpose() + kappa * (V / V0 - 1.0) * volume_hessian(p);
  }
  if (options_.large_strain) {
    // The backbone's tangent in place of the linear edge response's, 0.5 dL^T H dL unscaled.
    const Mat6 H1 = packed_hessian(e);
    Vec6 raw;
    for (int k = 0; k < 6; ++k) raw(k) = len(k) - edge_length(e, k);
    const Vec6 t1 = H1 * raw;
    for (int k = 0; k < 6; ++k) {
      const int a = kTetEdges[k][0], b = kTetEdges[k][1];
      const Eigen::Matrix<double, 1, 12> dt = (H1.row(k) * G - t1(k) / len(k) * G.row(k)) / len(k);
      K.block<3, 12>(3 * a, 0) += Y.col(k) * dt;
      K.block<3, 12>(3 * b, 0) -= Y.col(k) * dt;
      const Mat3 I = (t1(k) / len(k)) * Mat3::Identity();
      K.block<3, 3>(3 * a, 3 * a) -= I;
      K.block<3, 3>(3 * a, 3 * b) += I;
      K.block<3, 3>(3 * b, 3 * a) += I;
      K.block<3, 3>(3 * b, 3 * b) -= I;
    }
    const auto rest = gather(mesh_->nodes, e);
    K += neo_hookean_tangent(backbone(e), p, rest_shape_inverse(rest), signed_volume(rest[0], rest[1], rest[2], rest[3]));
  }
  return K;
}

}  // namespace viscera::tissue
