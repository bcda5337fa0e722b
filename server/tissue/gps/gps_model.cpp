#include "gps/gps_model.hpp"

#include <cmath>
#include <stdexcept>

#include "gps/gps_calibration.hpp"
#include "material/elasticity.hpp"

namespace viscera::tissue {

namespace {
Mat6 unpack(const double* h) {
  Mat6 H;
  int k = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) H(i, j) = H(j, i) = h[k++];
  return H;
}

// h = H dL with H packed as an upper triangle; fully unrolled by the compiler.
inline void packed_symmetric_multiply(const double* H, const double* dL, double* h) {
  for (int i = 0; i < 6; ++i) h[i] = 0.0;
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    h[i] += H[k++] * dL[i];
    for (int j = i + 1; j < 6; ++j, ++k) {
      h[i] += H[k] * dL[j];
      h[j] += H[k] * dL[i];
    }
  }
}
}  // namespace

GpsModel::GpsModel(std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials,
                   std::vector<std::uint16_t> material_of_tet, GpsOptions options)
    : ForceModel(std::move(mesh)), options_(options) {
  if (materials.empty()) throw std::invalid_argument("GpsModel: no material");
  if (!material_of_tet.empty() && material_of_tet.size() != element_count())
    throw std::invalid_argument("GpsModel: material_of_tet size differs from tet count");
  if (!(options_.volume_stiffness_fraction >= 0.0 && options_.volume_stiffness_fraction < 1.0))
    throw std::invalid_argument("GpsModel: volume_stiffness_fraction must lie in [0, 1)");
  const bool with_volume = options_.volume_stiffness_fraction > 0.0;
  std::vector<double> kappa(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    kappa[m] = options_.volume_stiffness_fraction * reuss_bulk_modulus(materials[m]);

  elements_.resize(element_count());
  if (with_volume) volume_.resize(element_count());
  for (std::size_t e = 0; e < element_count(); ++e) {
    const auto rest = gather(mesh_->nodes, e);
    const std::size_t m = material_of_tet.empty() ? 0 : material_of_tet[e];
    Mat6 H = gps_edge_hessian(rest, materials[m]);
    Element& el = elements_[e];
    el.v = mesh_->tets[e];
    for (int k = 0; k < 6; ++k) {
      el.rest_length[k] = (rest[kTetEdges[k][1]] - rest[kTetEdges[k][0]]).norm();
      el.inv_rest_length[k] = 1.0 / el.rest_length[k];
    }
    if (with_volume) {
      const double V0 = signed_volume(rest[0], rest[1], rest[2], rest[3]);
      volume_[e] = {V0, kappa[m]};
      const Vec6 hv = volume_in_elongations(rest);
      H -= (kappa[m] / V0) * hv * hv.transpose();
    }
    int k = 0;
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) el.H[k++] = H(i, j);
  }
}

std::string_view GpsModel::name() const {
  if (options_.variant == GpsVariant::paper)
    return volume_.empty() ? "gps" : "gps_volume";
  return volume_.empty() ? "gps_energy" : "gps_energy_volume";
}

Mat6 GpsModel::edge_hessian(std::size_t e) const { return unpack(elements_[e].H); }

Mat6 GpsModel::paper_constants(std::size_t e) const {
  Mat6 H = edge_hessian(e);
  if (!volume_.empty()) {
    const Vec6 hv = volume_in_elongations(gather(mesh_->nodes, e));
    H += (volume_[e].kappa / volume_[e].rest_volume) * hv * hv.transpose();
  }
  Vec6 inv;
  for (int k = 0; k < 6; ++k) inv(k) = elements_[e].inv_rest_length[k];
  return inv.asDiagonal() * H;
}

template <bool kEnergyConsistent, bool kVolume>
ForceStats GpsModel::add_forces_impl(std::span<const Vec3> x, std::span<Vec3> f) const {
  double max_strain = 0.0;
  const std::size_t n = elements_.size();
  for (std::size_t e = 0; e < n; ++e) {
    const Element& el = elements_[e];
    const Vec3 p[4] = {x[el.v[0]], x[el.v[1]], x[el.v[2]], x[el.v[3]]};
    double Y[6][3], L[6], dL[6];
    for (int k = 0; k < 6; ++k) {
      const Vec3& a = p[kTetEdges[k][0]];
      const Vec3& b = p[kTetEdges[k][1]];
      Y[k][0] = b[0] - a[0];
      Y[k][1] = b[1] - a[1];
      Y[k][2] = b[2] - a[2];
      L[k] = std::sqrt(Y[k][0] * Y[k][0] + Y[k][1] * Y[k][1] + Y[k][2] * Y[k][2]);
      dL[k] = L[k] - el.rest_length[k];
      const double s = std::abs(dL[k]) * el.inv_rest_length[k];
      max_strain = s > max_strain ? s : max_strain;
      if (s != s) max_strain = s;  // keep NaN visible
    }
    double t[6];
    packed_symmetric_multiply(el.H, dL, t);
    for (int k = 0; k < 6; ++k) t[k] *= kEnergyConsistent ? 1.0 / L[k] : el.inv_rest_length[k];
    Vec3 fv[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    for (int k = 0; k < 6; ++k) {
      const Vec3 fk(t[k] * Y[k][0], t[k] * Y[k][1], t[k] * Y[k][2]);
      fv[kTetEdges[k][0]] += fk;
      fv[kTetEdges[k][1]] -= fk;
    }
    if constexpr (kVolume) {
      const VolumeTerm& vt = volume_[e];
      const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0], e3 = p[3] - p[0];
      const Vec3 g1 = e2.cross(e3) / 6.0, g2 = e3.cross(e1) / 6.0, g3 = e1.cross(e2) / 6.0;
      const double V = e1.dot(g1);
      const double s = -vt.kappa * (V / vt.rest_volume - 1.0);
      fv[1] += s * g1;
      fv[2] += s * g2;
      fv[3] += s * g3;
      fv[0] -= s * (g1 + g2 + g3);
    }
    for (int i = 0; i < 4; ++i) f[el.v[i]] += fv[i];
  }
  return {max_strain};
}

ForceStats GpsModel::add_forces(std::span<const Vec3> x, std::span<Vec3> f) const {
  const bool ec = options_.variant == GpsVariant::energy_consistent;
  if (volume_.empty())
    return ec ? add_forces_impl<true, false>(x, f) : add_forces_impl<false, false>(x, f);
  return ec ? add_forces_impl<true, true>(x, f) : add_forces_impl<false, true>(x, f);
}

double GpsModel::energy(std::span<const Vec3> x) const {
  double sum = 0.0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const Element& el = elements_[e];
    const auto p = gather(x, e);
    double dL[6], h[6];
    for (int k = 0; k < 6; ++k)
      dL[k] = (p[kTetEdges[k][1]] - p[kTetEdges[k][0]]).norm() - el.rest_length[k];
    packed_symmetric_multiply(el.H, dL, h);
    for (int k = 0; k < 6; ++k) sum += 0.5 * dL[k] * h[k];
    if (!volume_.empty()) {
      const double r = signed_volume(p[0], p[1], p[2], p[3]) / volume_[e].rest_volume - 1.0;
      sum += 0.5 * volume_[e].kappa * volume_[e].rest_volume * r * r;
    }
  }
  return sum;
}

Mat12 GpsModel::element_tangent(std::span<const Vec3> x, std::size_t e) const {
  // f = P t with P_e = (+Y_e at a, -Y_e at b), t = S h, h = H dL, dL = G dx,
  // G_e = (-y_e at a, +y_e at b), y_e = Y_e / L_e. K = -df/dx (see MODEL.md section 1).
  const Element& el = elements_[e];
  const auto p = gather(x, e);
  const Mat6 H = unpack(el.H);
  Mat6x12 G = Mat6x12::Zero();
  Vec6 L, dL;
  Eigen::Matrix<double, 3, 6> Y;
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    Y.col(k) = p[b] - p[a];
    L(k) = Y.col(k).norm();
    dL(k) = L(k) - el.rest_length[k];
    G.block<1, 3>(k, 3 * a) = -Y.col(k).transpose() / L(k);
    G.block<1, 3>(k, 3 * b) = Y.col(k).transpose() / L(k);
  }
  const Vec6 h = H * dL;
  const bool ec = options_.variant == GpsVariant::energy_consistent;
  Mat12 K = Mat12::Zero();
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    const double s = ec ? 1.0 / L(k) : el.inv_rest_length[k];
    const double tk = s * h(k);
    // Material part: -P_k dt_k/dx with dt_k/dx = s (H G)_k [- h_k / L_k^2 G_k for EC].
    Eigen::Matrix<double, 1, 12> dt = s * (H.row(k) * G);
    if (ec) dt -= h(k) / (L(k) * L(k)) * G.row(k);
    K.block<3, 12>(3 * a, 0) -= Y.col(k) * dt;
    K.block<3, 12>(3 * b, 0) += Y.col(k) * dt;
    // Geometric part: -t_k dP_k/dx, dP_k/dx = [[-I, I], [I, -I]] on (a, b).
    const Mat3 I = tk * Mat3::Identity();
    K.block<3, 3>(3 * a, 3 * a) += I;
    K.block<3, 3>(3 * a, 3 * b) -= I;
    K.block<3, 3>(3 * b, 3 * a) -= I;
    K.block<3, 3>(3 * b, 3 * b) += I;
  }
  if (!volume_.empty()) {
    const VolumeTerm& vt = volume_[e];
    const Vec12 g = volume_gradient(p);
    const double V = signed_volume(p[0], p[1], p[2], p[3]);
    K += (vt.kappa / vt.rest_volume) * g * g.transpose() +
         vt.kappa * (V / vt.rest_volume - 1.0) * volume_hessian(p);
  }
  return K;
}

}  // namespace viscera::tissue
