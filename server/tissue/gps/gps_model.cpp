#include "viscera/tissue/gps/gps_model.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "viscera/tissue/gps/fung_map.hpp"
#include "viscera/tissue/gps/gps_calibration.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/viscoelastic/standard_linear_solids.hpp"

namespace viscera::tissue {

namespace {
constexpr int L = GpsModel::kLanes;
constexpr std::size_t kPrefetchAhead = 2;  // blocks (1, 2 and 4 measured at 96k: 2 best)
// Streams larger than this come from DRAM rather than the caches; only then does prefetching pay.
constexpr std::size_t kPrefetchAboveBytes = std::size_t{16} << 20;
}  // namespace

GpsModel::GpsModel(std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials, std::vector<std::uint16_t> material_of_tet, GpsOptions options)
    : ForceModel(std::move(mesh)), options_(std::move(options)) {
  if (materials.empty()) throw std::invalid_argument("GpsModel: no material");
  if (!material_of_tet.empty() && material_of_tet.size() != element_count())
    throw std::invalid_argument("GpsModel: material_of_tet size differs from tet count");
  for (const std::uint16_t m : material_of_tet)
    if (m >= materials.size()) throw std::invalid_argument("GpsModel: material_of_tet names a material that was not given");
  if (!(options_.volume_stiffness_fraction >= 0.0 && options_.volume_stiffness_fraction < 1.0))
    throw std::invalid_argument("GpsModel: volume_stiffness_fraction must lie in [0, 1)");
  with_volume_ = options_.volume_stiffness_fraction > 0.0;
  options_.mechanisms.validate();
  if (options_.large_strain) {
    if (options_.variant != GpsVariant::energy_consistent) throw std::invalid_argument("the large-strain GPS is energy-consistent");
    if (with_volume_) throw std::invalid_argument("the large-strain GPS has no volume term: its backbone holds the volume");
    if (options_.mechanisms.energy_map())
      throw std::invalid_argument("the large-strain GPS takes the stiffening in its edge-map form only (not \"qlv_form\": \"energy\")");
    // Its memory relaxes the backbone's stress (docs/TISSUE.md, "Large strain"); stiffening and
    // first-load softening would need memory of their own.
    const GpsMechanisms& m = options_.mechanisms;
    if (m.viscous.active() && (m.stiffening.active() || m.asymmetry.active()))
      throw std::invalid_argument("the large-strain GPS takes viscoelasticity or strain stiffening, not both");
    if (m.softening.active()) throw std::invalid_argument("the large-strain GPS has no first-load softening");
    if (m.viscous.bulk_differs()) {
      for (std::size_t l = 0; l < m.viscous.mechanisms(); ++l)
        if (m.viscous.bulk(l) != 0.0)
          throw std::invalid_argument("the large-strain GPS relaxes the bulk as the shear (bulk_q equal to shear_q) or not at all (bulk_q absent)");
      if (m.viscous.kelvin_voigt_time_s > 0)
        throw std::invalid_argument("the large-strain GPS takes a Kelvin-Voigt time only where the bulk relaxes as the shear");
      deviatoric_memory_ = true;
    }
  }
  const GpsViscous& viscous = options_.mechanisms.viscous;
  mechanisms_ = viscous.mechanisms();
  materials_ = std::move(materials);
  material_of_tet_ = std::move(material_of_tet);
  kappa_.resize(materials_.size());
  for (std::size_t m = 0; m < materials_.size(); ++m) kappa_[m] = options_.volume_stiffness_fraction * reuss_bulk_modulus(materials_[m]);
  if (options_.large_strain)
    for (const Mat6& D : materials_) backbone_.push_back(neo_hookean_of(D));
  const std::size_t n = element_count();
  blocks_.resize((n + L - 1) / L);
  if (viscous.bulk_differs() && !options_.large_strain) bulk_.resize(blocks_.size());  // the backbone splits its own
  if (options_.large_strain) neo_.resize(blocks_.size());
  for (std::size_t slot = 0; slot < blocks_.size() * L; ++slot) write_lane(slot);
}

std::size_t GpsModel::material_of(std::size_t e) const { return material_of_tet_.empty() ? 0 : material_of_tet_[e]; }

Mat6 GpsModel::calibrated_hessian(const std::array<Vec3, 4>& rest, std::size_t m) const {
  Mat6 H = gps_edge_hessian(rest, materials_[m]);
  if (with_volume_) {
    // Remove the volume term's small-strain stiffness so that the sum still equals linear FE.
    const Vec6 hv = volume_in_elongations(rest);
    H -= (kappa_[m] / signed_volume(rest[0], rest[1], rest[2], rest[3])) * hv * hv.transpose();
  }
  return H;
}

void GpsModel::write_lane(std::size_t slot) {
  const std::size_t n = element_count();
  const bool padding = slot >= n;
  const std::size_t e = padding ? (slot / L) * L : slot;  // padding copies the block's first element
  Block& b = blocks_[slot / L];
  const int j = static_cast<int>(slot % L);
  const auto rest = gather(mesh_->nodes, e);
  const std::size_t m = material_of(e);
  // A padding lane contributes nothing: its H is zero, so it is not calibrated (a cut that grows
  // the model rewrites up to seven of them).
  Mat6 H = padding ? Mat6::Zero().eval() : calibrated_hessian(rest, m);
  const double V0 = signed_volume(rest[0], rest[1], rest[2], rest[3]);
  if (!bulk_.empty()) {
    // The volumetric part of H is rank one: (K_Reuss / V0) hv hv^T (hv: J^T hv = grad V).
    const Vec6 hv = volume_in_elongations(rest);
    BulkBlock& bb = bulk_[slot / L];
    for (int k = 0; k < 6; ++k) bb.hv[k][j] = hv(k);
    bb.scale[j] = padding ? 0.0 : (reuss_bulk_modulus(materials_[m]) - (with_volume_ ? kappa_[m] : 0.0)) / V0;
  }
  for (int k = 0; k < 4; ++k) b.v[k][j] = mesh_->tets[e][k];
  for (int k = 0; k < 6; ++k) {
    b.rest_length[k][j] = (rest[kTetEdges[k][1]] - rest[kTetEdges[k][0]]).norm();
    b.inv_rest_length[k][j] = 1.0 / b.rest_length[k][j];
  }
  int k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) b.H[k++][j] = H(r, c);
  b.rest_volume[j] = V0;
  b.kappa[j] = (with_volume_ && !padding) ? kappa_[m] : 0.0;
  if (!neo_.empty()) {
    NeoBlock& nb = neo_[slot / L];
    const Mat3 dm_inv = rest_shape_inverse(rest);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) nb.dm_inv[3 * r + c][j] = dm_inv(r, c);
    nb.mu[j] = padding ? 0.0 : backbone_[m].mu;
    nb.lam[j] = padding ? 0.0 : backbone_[m].lam;
    nb.alpha[j] = padding ? 1.0 : backbone_[m].alpha();
  }
}

std::string_view GpsModel::name() const {
  if (options_.large_strain) return "gps_large_strain";
  if (options_.variant == GpsVariant::paper) return with_volume_ ? "gps_volume" : "gps";
  return with_volume_ ? "gps_energy_volume" : "gps_energy";
}

Mat6 GpsModel::packed_hessian(std::size_t e) const {
  const Block& b = blocks_[e / L];
  const std::size_t j = e % L;
  Mat6 H;
  int k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c, ++k) H(r, c) = H(c, r) = b.H[k][j];
  return H;
}

double GpsModel::edge_length(std::size_t e, int k) const { return blocks_[e / L].rest_length[k][e % L]; }

Mat6 GpsModel::edge_hessian(std::size_t e) const { return packed_hessian(e); }

Mat6 GpsModel::paper_constants(std::size_t e) const {
  Mat6 H = packed_hessian(e);
  if (with_volume_) {
    const Block& b = blocks_[e / L];
    const Vec6 hv = volume_in_elongations(gather(mesh_->nodes, e));
    H += (b.kappa[e % L] / b.rest_volume[e % L]) * hv * hv.transpose();
  }
  Vec6 inv;
  for (int k = 0; k < 6; ++k) inv(k) = 1.0 / edge_length(e, k);
  return inv.asDiagonal() * H;
}

template <bool kEnergyConsistent, bool kVolume, bool kMemory>
ForceStats GpsModel::add_forces_impl(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate* memory, std::size_t first_block,
                                     std::size_t end_block) const {
  const Vec3* X = mesh_->nodes.data();
  double max_strain[L] = {}, nan_probe[L] = {};
  // Memory: per block (1 + mechanisms) x 6 x L doubles: previous elongations, then zeta_l; with
  // first-load softening 2 x 6 x L more: each edge's largest strain in tension, then in compression.
  const GpsMechanisms& mech = options_.mechanisms;
  const std::size_t nm = mechanisms_;
  const std::size_t stride = memory_stride();
  const double softening = mech.softening.d;
  const std::size_t soft_at = softening_offset();
  double me[8], ma[8], mc[8], ys[8], yb[8];
  double rate_scale = 0.0;
  const double dt = memory ? memory->dt_s : 0.0;
  if constexpr (kMemory) {
    for (std::size_t l = 0; l < nm; ++l) {
      const MemoryStep st = MemoryStep::make(mech.viscous.omega_rad_s[l], dt);
      me[l] = st.e;
      ma[l] = st.a;
      mc[l] = st.c;
      ys[l] = mech.viscous.shear_weight[l];
      yb[l] = mech.viscous.bulk(l);
    }
    rate_scale = dt > 0 ? mech.viscous.kelvin_voigt_time_s / dt : 0.0;
  }
  const double qlv = mech.stiffening.b;
  const bool qlv_energy = mech.energy_map();
  const double ratio = mech.asymmetry.compression_ratio;
  const StiffeningShape shape = mech.stiffening.shape;
  // When the two streams (elements, memory) come from DRAM, the hardware prefetcher does not keep
  // them ahead: at 96k tets asking for them two blocks early makes a step 25% faster (AMD EPYC).
  // While they fit in the caches it costs: 9% on a 12k step (Intel Xeon). Into all cache levels
  // (locality 3): the non-temporal hint made the Xeon's 12k and 96k steps 2.6-2.9x slower.
  const bool prefetch = blocks_.size() * (sizeof(Block) + (kMemory ? stride * sizeof(double) : 0)) > kPrefetchAboveBytes;
  for (std::size_t bi = first_block; bi < end_block; ++bi) {
    const Block& b = blocks_[bi];
    if (prefetch && bi + kPrefetchAhead < end_block) {
      const char* next = reinterpret_cast<const char*>(&blocks_[bi + kPrefetchAhead]);
      for (std::size_t o = 0; o < sizeof(Block); o += 64) __builtin_prefetch(next + o, 0, 3);
      if constexpr (kMemory) {
        const char* mem = reinterpret_cast<const char*>(memory->before.data() + (bi + kPrefetchAhead) * stride);
        for (std::size_t o = 0; o < stride * sizeof(double); o += 64) __builtin_prefetch(mem + o, 1, 3);
      }
    }
    // Gather: current positions, and displacements u = x - X (exact for x near X).
    double p[4][3][L], u[4][3][L];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < L; ++j) {
        const Vec3& xi = x[b.v[i][j]];
        const Vec3& Xi = X[b.v[i][j]];
        for (int c = 0; c < 3; ++c) {
          p[i][c][j] = xi[c];
          u[i][c][j] = xi[c] - Xi[c];
        }
      }
    double Y[6][3][L], len[6][L], dL[6][L];
    for (int k = 0; k < 6; ++k) {
      const int a = kTetEdges[k][0], c = kTetEdges[k][1];
#pragma omp simd
      for (int j = 0; j < L; ++j) {
        // Elongation from displacements, free of the cancellation in |Y| - L0 at small strain:
        // |Y|^2 - L0^2 = (2 Y0 + du) . du with du = u_b - u_a and Y0 = Y - du.
        const double y0 = p[c][0][j] - p[a][0][j], y1 = p[c][1][j] - p[a][1][j], y2 = p[c][2][j] - p[a][2][j];
        const double d0 = u[c][0][j] - u[a][0][j], d1 = u[c][1][j] - u[a][1][j], d2 = u[c][2][j] - u[a][2][j];
        Y[k][0][j] = y0;
        Y[k][1][j] = y1;
        Y[k][2][j] = y2;
        const double l = std::sqrt(y0 * y0 + y1 * y1 + y2 * y2);
        const double s = (2.0 * y0 - d0) * d0 + (2.0 * y1 - d1) * d1 + (2.0 * y2 - d2) * d2;
        len[k][j] = l;
        dL[k][j] = s / (l + b.rest_length[k][j]);
      }
#pragma omp simd
      for (int j = 0; j < L; ++j) {
        max_strain[j] = std::max(max_strain[j], std::fabs(dL[k][j]) * b.inv_rest_length[k][j]);
        nan_probe[j] += dL[k][j];  // a NaN anywhere survives in the sum; max() would drop it
      }
    }
    double raw[6][L];  // the large-strain GPS: the elongations before any map or memory
    const bool large = !neo_.empty();
    // The large-strain GPS without stiffening: its edges carry nothing (its memory is the backbone's).
    const bool edges_idle = large && !(qlv > 0);
    if (large && !edges_idle)
      for (int k = 0; k < 6; ++k)
#pragma omp simd
        for (int j = 0; j < L; ++j) raw[k][j] = dL[k][j];
    double strain[6][L];  // first-load softening: the edge strains before any map
    if constexpr (kMemory)
      if (softening > 0)
        for (int k = 0; k < 6; ++k)
#pragma omp simd
          for (int j = 0; j < L; ++j) strain[k][j] = dL[k][j] * b.inv_rest_length[k][j];
    double dh[6][L];  // energy form: h'(e), which multiplies the tensions
    if (qlv > 0 || qlv_energy) {  // Fung: elongation measure L0 g(e) or L0 h(e), e = dL / L0
      if (qlv_energy) {
        for (int k = 0; k < 6; ++k)
#pragma omp simd
          for (int j = 0; j < L; ++j) {
            double h, dhk;
            lanes::edge_energy_map(qlv, ratio, shape, dL[k][j] * b.inv_rest_length[k][j], h, dhk);
            dL[k][j] = b.rest_length[k][j] * h;
            dh[k][j] = dhk;
          }
      } else {
        for (int k = 0; k < 6; ++k)
          for (int j = 0; j < L; ++j) dL[k][j] = b.rest_length[k][j] * std::expm1(qlv * dL[k][j] * b.inv_rest_length[k][j]) / qlv;
      }
    }
    double bulk_part[6][L];  // a_b - a_s, for bulk relaxation that differs from shear
    // Tensions t = S H dL (H packed, symmetric). The energy form of Fung's stiffening relaxes the
    // elastic tensions h' (H h) themselves (3D QLV: the hereditary integral over the elastic
    // response, exact in 1D); otherwise the memory filters the elongations and H acts after it.
    double t[6][L];
    const auto apply_h = [&](double(&v)[6][L]) {
      for (int k = 0; k < 6; ++k)
#pragma omp simd
        for (int j = 0; j < L; ++j) t[k][j] = 0.0;
      int h = 0;
      for (int r = 0; r < 6; ++r) {
#pragma omp simd
        for (int j = 0; j < L; ++j) t[r][j] += b.H[h][j] * v[r][j];
        ++h;
        for (int c = r + 1; c < 6; ++c, ++h)
#pragma omp simd
          for (int j = 0; j < L; ++j) {
            t[r][j] += b.H[h][j] * v[c][j];
            t[c][j] += b.H[h][j] * v[r][j];
          }
      }
    };
    if (qlv_energy) {
      apply_h(dL);
      for (int k = 0; k < 6; ++k)
#pragma omp simd
        for (int j = 0; j < L; ++j) t[k][j] *= dh[k][j];
    }
    double(&filtered)[6][L] = qlv_energy ? t : dL;
    double block_probe = 0.0;  // NaN if any elongation of the block is not finite
    if constexpr (kMemory) {
      // Per lane first: one long scalar chain of 48 dependent adds cost a quarter of the loop.
      double lane_probe[L] = {};
      for (int k = 0; k < 6; ++k)
#pragma omp simd
        for (int j = 0; j < L; ++j) lane_probe[j] += 0.0 * filtered[k][j];
      for (int j = 0; j < L; ++j) block_probe += lane_probe[j];
    }
    // zeta_l <- e zeta_l + a q_prev + c (q - q_prev): exact for q linear over the step (dt = 0
    // gives e = 1, a = c = 0: the memory stays); q the elongations (or tensions), or for the
    // large-strain GPS its backbone's second Piola-Kirchhoff stress.
    const double* in = kMemory ? memory->before.data() + bi * stride : nullptr;
    // A block with a non-finite elongation leaves its memory untouched (it is reported as an
    // instability by the caller); its new values go to a local scratch instead.
    double scratch[(1 + 8 + 2) * 6 * L];
    double* out = kMemory ? (block_probe == 0.0 ? memory->after.data() + bi * stride : scratch) : nullptr;
    if constexpr (kMemory) {
      if (!large) {  // the large-strain GPS's memory is its backbone's (below)
        if (softening > 0) {
          // Below the largest strain seen in the same sense, the elastic response is softened; the
          // extremes then take this evaluation's strain (read before written: in place is fine).
          const double* peak_in = in + soft_at;
          double* peak_out = out + soft_at;
          for (int k = 0; k < 6; ++k)
#pragma omp simd
            for (int j = 0; j < L; ++j) {
              const double e = strain[k][j], a = std::fabs(e);
              const double tension = peak_in[k * L + j], compression = peak_in[(6 + k) * L + j];
              const double peak = e >= 0 ? tension : compression;
              filtered[k][j] *= a < peak ? 1.0 - softening * (1.0 - a / peak) : 1.0;
              peak_out[k * L + j] = e >= 0 ? std::max(tension, a) : tension;
              peak_out[(6 + k) * L + j] = e < 0 ? std::max(compression, a) : compression;
            }
        }
        for (int k = 0; k < 6; ++k) {
          double zs[L] = {}, zb[L] = {};
          const double* prev = in + k * L;
          for (std::size_t l = 0; l < nm; ++l) {
            const double* zin = in + ((1 + l) * 6 + static_cast<std::size_t>(k)) * L;
            double* zout = out + ((1 + l) * 6 + static_cast<std::size_t>(k)) * L;
            const double e = me[l], a = ma[l], c = mc[l], y_s = ys[l], y_b = yb[l];
#pragma omp simd
            for (int j = 0; j < L; ++j) {
              const double z = e * zin[j] + a * prev[j] + c * (filtered[k][j] - prev[j]);
              zout[j] = z;
              zs[j] += y_s * z;
              zb[j] += y_b * z;
            }
          }
          double* prev_out = out + k * L;
#pragma omp simd
          for (int j = 0; j < L; ++j) {
            const double dl = filtered[k][j];
            const double rate = (dl - prev[j]) * rate_scale;  // Kelvin-Voigt: tau d(dL)/dt
            prev_out[j] = dl;
            filtered[k][j] = dl - zs[j] + rate;  // a_s: the relaxed (shear) elongation (or tension)
            bulk_part[k][j] = zs[j] - zb[j];  // a_b - a_s
          }
        }
      }
    }
    if (large && !edges_idle)  // the linear edge response is the backbone's: the edges keep what departs from it
      for (int k = 0; k < 6; ++k)
#pragma omp simd
        for (int j = 0; j < L; ++j) dL[k][j] -= raw[k][j];
    if (!qlv_energy && !edges_idle) apply_h(dL);
    if constexpr (kMemory) {
      if (!bulk_.empty()) {  // + (K/V0) hv (hv . (a_b - a_s))
        const BulkBlock& bb = bulk_[bi];
#pragma omp simd
        for (int j = 0; j < L; ++j) {
          double proj = 0.0;
          for (int k = 0; k < 6; ++k) proj += bb.hv[k][j] * bulk_part[k][j];
          for (int k = 0; k < 6; ++k) t[k][j] += bb.scale[j] * bb.hv[k][j] * proj;
        }
      }
    }
    for (int k = 0; k < 6 && !edges_idle; ++k)
#pragma omp simd
      for (int j = 0; j < L; ++j) t[k][j] *= kEnergyConsistent ? 1.0 / len[k][j] : b.inv_rest_length[k][j];
    // Vertex forces: +t Y on a, -t Y on b, plus the signed-volume term.
    double fv[4][3][L] = {};
    for (int k = 0; k < 6 && !edges_idle; ++k) {
      const int a = kTetEdges[k][0], c = kTetEdges[k][1];
      for (int d = 0; d < 3; ++d)
#pragma omp simd
        for (int j = 0; j < L; ++j) {
          const double fk = t[k][j] * Y[k][d][j];
          fv[a][d][j] += fk;
          fv[c][d][j] -= fk;
        }
    }
    if constexpr (kVolume) {
#pragma omp simd
      for (int j = 0; j < L; ++j) {
        double e1[3], e2[3], e3[3];
        for (int d = 0; d < 3; ++d) {
          e1[d] = p[1][d][j] - p[0][d][j];
          e2[d] = p[2][d][j] - p[0][d][j];
          e3[d] = p[3][d][j] - p[0][d][j];
        }
        // 6 x the volume gradients (the 1/6 goes into the scale: divisions are the slow unit)
        const double g1[3] = {e2[1] * e3[2] - e2[2] * e3[1], e2[2] * e3[0] - e2[0] * e3[2], e2[0] * e3[1] - e2[1] * e3[0]};
        const double g2[3] = {e3[1] * e1[2] - e3[2] * e1[1], e3[2] * e1[0] - e3[0] * e1[2], e3[0] * e1[1] - e3[1] * e1[0]};
        const double g3[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const double V = (e1[0] * g1[0] + e1[1] * g1[1] + e1[2] * g1[2]) * (1.0 / 6);
        const double scale = -b.kappa[j] * (V / b.rest_volume[j] - 1.0) * (1.0 / 6);
        for (int d = 0; d < 3; ++d) {
          fv[1][d][j] += scale * g1[d];
          fv[2][d][j] += scale * g2[d];
          fv[3][d][j] += scale * g3[d];
          fv[0][d][j] -= scale * (g1[d] + g2[d] + g3[d]);
        }
      }
    }
    if (large) {
      // The backbone: P = mu F + lam (J - alpha) cof(F), F = Ds Dm^-1; vertex forces -V0 P Dm^-T.
      // With memory, P = P_e + F (tau dq/dt - sum_l y_l zeta_l): the memory relaxes the second
      // Piola-Kirchhoff stress q = S = mu I + lam (J - alpha) cof^T cof / J, or where the bulk does
      // not relax q = DEV[S] = mu (I - tr(C) cof^T cof / (3 J^2)) (neo_hookean_backbone.hpp).
      // In stages over the lanes, as the edges' memory: the mechanisms' loop inside a lane's
      // would not vectorise.
      const NeoBlock& nb = neo_[bi];
      double F[3][3][L], P[3][3][L], q_now[6][L];
#pragma omp simd
      for (int j = 0; j < L; ++j) {
        double ds[3][3], Fl[3][3];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) ds[r][c] = p[c + 1][r][j] - p[0][r][j];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) Fl[r][c] = ds[r][0] * nb.dm_inv[c][j] + ds[r][1] * nb.dm_inv[3 + c][j] + ds[r][2] * nb.dm_inv[6 + c][j];
        // cof(F), column by column: F1 x F2, F2 x F0, F0 x F1 (Fc: column c).
        double C[3][3];
        for (int c = 0; c < 3; ++c) {
          const int c1 = (c + 1) % 3, c2 = (c + 2) % 3;
          C[0][c] = Fl[1][c1] * Fl[2][c2] - Fl[2][c1] * Fl[1][c2];
          C[1][c] = Fl[2][c1] * Fl[0][c2] - Fl[0][c1] * Fl[2][c2];
          C[2][c] = Fl[0][c1] * Fl[1][c2] - Fl[1][c1] * Fl[0][c2];
        }
        const double J = Fl[0][0] * C[0][0] + Fl[1][0] * C[1][0] + Fl[2][0] * C[2][0];
        const double s = nb.lam[j] * (J - nb.alpha[j]);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) {
            F[r][c][j] = Fl[r][c];
            P[r][c][j] = nb.mu[j] * Fl[r][c] + s * C[r][c];
          }
        if constexpr (kMemory) {
          const double jf = std::max(J, kBackboneMemoryFloorJ);
          double trC = 0.0;
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) trC += Fl[r][c] * Fl[r][c];
          const double diagonal = nb.mu[j], coupling = deviatoric_memory_ ? -nb.mu[j] * trC / (3 * jf * jf) : s / jf;
          for (int q = 0; q < 6; ++q) {
            const int a = kVoigtPairs[q][0], c = kVoigtPairs[q][1];
            q_now[q][j] = (a == c ? diagonal : 0.0) + coupling * (C[0][a] * C[0][c] + C[1][a] * C[1][c] + C[2][a] * C[2][c]);
          }
        }
      }
      if constexpr (kMemory) {
        double W[6][L];
        for (int q = 0; q < 6; ++q) {
          double zs[L] = {};
          const double* prev = in + q * L;
          for (std::size_t l = 0; l < nm; ++l) {
            const double* zin = in + ((1 + l) * 6 + static_cast<std::size_t>(q)) * L;
            double* zout = out + ((1 + l) * 6 + static_cast<std::size_t>(q)) * L;
            const double e = me[l], a = ma[l], c = mc[l], y = ys[l];
#pragma omp simd
            for (int j = 0; j < L; ++j) {
              const double z = e * zin[j] + a * prev[j] + c * (q_now[q][j] - prev[j]);
              zout[j] = z;
              zs[j] += y * z;
            }
          }
          double* prev_out = out + q * L;
#pragma omp simd
          for (int j = 0; j < L; ++j) {
            W[q][j] = (q_now[q][j] - prev[j]) * rate_scale - zs[j];
            prev_out[j] = q_now[q][j];
          }
        }
        constexpr int kAt[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};  // Voigt slot of (row, column)
#pragma omp simd
        for (int j = 0; j < L; ++j)
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) P[r][c][j] += F[r][0][j] * W[kAt[0][c]][j] + F[r][1][j] * W[kAt[1][c]][j] + F[r][2][j] * W[kAt[2][c]][j];
      }
#pragma omp simd
      for (int j = 0; j < L; ++j) {
        const double V0 = b.rest_volume[j];
        for (int r = 0; r < 3; ++r) {
          double sum = 0.0;
          for (int v = 0; v < 3; ++v) {  // -V0 (P Dm^-T)_{r v}: the force on vertex v + 1
            const double h = -V0 * (P[r][0][j] * nb.dm_inv[3 * v][j] + P[r][1][j] * nb.dm_inv[3 * v + 1][j] + P[r][2][j] * nb.dm_inv[3 * v + 2][j]);
            fv[v + 1][r][j] += h;
            sum += h;
          }
          fv[0][r][j] -= sum;
        }
      }
    }
    // Scatter (lanes may share vertices: scalar adds).
    for (int j = 0; j < L; ++j)
      for (int i = 0; i < 4; ++i) {
        Vec3& fi = f[b.v[i][j]];
        fi[0] += fv[i][0][j];
        fi[1] += fv[i][1][j];
        fi[2] += fv[i][2][j];
      }
  }
  double worst = 0.0, probe = 0.0;
  for (int j = 0; j < L; ++j) {
    worst = std::max(worst, max_strain[j]);
    probe += nan_probe[j];
  }
  return {std::isnan(probe) ? std::numeric_limits<double>::quiet_NaN() : worst};
}

ForceStats GpsModel::add_forces(std::span<const Vec3> x, std::span<Vec3> f) const { return add_forces(x, f, MemoryUpdate{}, ElementPart{}); }

std::size_t GpsModel::memory_size() const { return options_.mechanisms.has_memory() ? blocks_.size() * memory_stride() : 0; }

ForceStats GpsModel::add_forces(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory) const {
  return add_forces(x, f, memory, ElementPart{});
}

std::pair<std::size_t, std::size_t> GpsModel::part_blocks(ElementPart part) const {
  if (part.count == 0 || part.index >= part.count) throw std::invalid_argument("GpsModel: part index outside the part count");
  const std::size_t n = blocks_.size();
  return {n * part.index / part.count, n * (part.index + 1) / part.count};
}

std::pair<std::size_t, std::size_t> GpsModel::part_elements(ElementPart part) const {
  const auto [b0, b1] = part_blocks(part);
  // A block's padding lanes repeat its first element: within the range.
  return {std::min(b0 * L, element_count()), std::min(b1 * L, element_count())};
}

ForceStats GpsModel::add_forces(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory, ElementPart part) const {
  const auto [b0, b1] = part_blocks(part);
  const bool ec = options_.variant == GpsVariant::energy_consistent;
  // Without memory attached (or none to keep): the unrelaxed (instantaneous) response.
  if (memory_size() == 0 || memory.before.size() != memory_size() || memory.after.size() != memory_size()) {
    if (!with_volume_)
      return ec ? add_forces_impl<true, false, false>(x, f, nullptr, b0, b1) : add_forces_impl<false, false, false>(x, f, nullptr, b0, b1);
    return ec ? add_forces_impl<true, true, false>(x, f, nullptr, b0, b1) : add_forces_impl<false, true, false>(x, f, nullptr, b0, b1);
  }
  if (!with_volume_)
    return ec ? add_forces_impl<true, false, true>(x, f, &memory, b0, b1) : add_forces_impl<false, false, true>(x, f, &memory, b0, b1);
  return ec ? add_forces_impl<true, true, true>(x, f, &memory, b0, b1) : add_forces_impl<false, true, true>(x, f, &memory, b0, b1);
}

}  // namespace viscera::tissue
