#include "viscera/tissue/fem/finite_element_model.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>
#include <stdexcept>

#include "viscera/tissue/fem/polar_decomposition.hpp"

namespace viscera::tissue {

FiniteElementModel::FiniteElementModel(std::shared_ptr<const TetMesh> mesh, FeKind kind, std::vector<Mat6> materials,
                                       std::vector<std::uint16_t> material_of_tet)
    : ForceModel(std::move(mesh)), kind_(kind), materials_(std::move(materials)), material_of_tet_(std::move(material_of_tet)) {
  if (materials_.empty()) throw std::invalid_argument("FiniteElementModel: no material");
  if (!material_of_tet_.empty() && material_of_tet_.size() != element_count())
    throw std::invalid_argument("FiniteElementModel: material_of_tet size differs from tet count");
  elements_.resize(element_count());
  for (std::size_t e = 0; e < element_count(); ++e) {
    const Mat3 dm = edge_matrix(gather(mesh_->nodes, e));
    elements_[e] = {dm.inverse(), dm.determinant() / 6.0};
  }
}

std::string_view FiniteElementModel::name() const { return kind_ == FeKind::linear ? "linear" : "corotational"; }

Mat3 FiniteElementModel::deformation_gradient(std::span<const Vec3> x, std::size_t e) const {
  return edge_matrix(gather(x, e)) * elements_[e].dm_inv;
}

ForceStats FiniteElementModel::add_forces(std::span<const Vec3> x, std::span<Vec3> f) const {
  const auto& tets = mesh_->tets;
  double max_strain = 0.0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const Element& el = elements_[e];
    const Tet& t = tets[e];
    const Vec3& x0 = x[t[0]];
    Mat3 ds;
    ds.col(0) = x[t[1]] - x0;
    ds.col(1) = x[t[2]] - x0;
    ds.col(2) = x[t[3]] - x0;
    const Mat3 F = ds * el.dm_inv;
    Mat3 R = Mat3::Identity();
    Mat3 local = F;
    if (kind_ == FeKind::corotational) {
      R = polar_rotation(F);
      local = R.transpose() * F;
    }
    const Mat3 strain = 0.5 * (local + local.transpose()) - Mat3::Identity();
    const double s = strain.cwiseAbs().maxCoeff();
    if (!(s <= max_strain)) max_strain = s;  // propagates NaN
    const Mat3 sigma = voigt_to_stress(material(e) * strain_to_voigt(strain));
    // Forces on vertices 1..3 are the columns of -V P Dm^-T; vertex 0 balances them.
    const Mat3 H = -el.volume * (R * sigma) * el.dm_inv.transpose();
    f[t[1]] += H.col(0);
    f[t[2]] += H.col(1);
    f[t[3]] += H.col(2);
    f[t[0]] -= H.col(0) + H.col(1) + H.col(2);
  }
  return {max_strain};
}

Vec6 FiniteElementModel::element_stress(std::span<const Vec3> x, std::size_t e) const {
  const Mat3 F = deformation_gradient(x, e);
  const Mat3 local = kind_ == FeKind::corotational ? Mat3(polar_rotation(F).transpose() * F) : F;
  const Mat3 strain = 0.5 * (local + local.transpose()) - Mat3::Identity();
  return material(e) * strain_to_voigt(strain);
}

double FiniteElementModel::energy(std::span<const Vec3> x) const {
  double sum = 0.0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const Mat3 F = deformation_gradient(x, e);
    const Mat3 local = kind_ == FeKind::corotational ? Mat3(polar_rotation(F).transpose() * F) : F;
    const Vec6 eps = strain_to_voigt(0.5 * (local + local.transpose()) - Mat3::Identity());
    sum += 0.5 * elements_[e].volume * eps.dot(material(e) * eps);
  }
  return sum;
}

Mat12 FiniteElementModel::element_tangent(std::span<const Vec3> x, std::size_t e) const {
  const Element& el = elements_[e];
  const Mat6x12 B = strain_displacement(el.dm_inv);
  Mat12 K = el.volume * B.transpose() * material(e) * B;
  if (kind_ == FeKind::corotational) {
    // K = R K0 R^T with R block-diagonal (the usual corotational tangent; it omits dR/dx).
    const Mat3 R = polar_rotation(deformation_gradient(x, e));
    Mat12 Rb = Mat12::Zero();
    for (int i = 0; i < 4; ++i) Rb.block<3, 3>(3 * i, 3 * i) = R;
    K = Rb * K * Rb.transpose();
  }
  return K;
}

}  // namespace viscera::tissue
