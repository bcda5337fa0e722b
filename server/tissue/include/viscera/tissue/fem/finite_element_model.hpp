#pragma once  // SPDX-License-Identifier: Apache-2.0
// Linear-tetrahedron finite elements, the two comparison models of docs/MODEL.md section 1:
//  - linear:       small-strain FE, f = -K (x - X). Not rotation invariant.
//  - corotational: f = -R K (R^T x - X), R the rotation of the polar decomposition of F.
// Both are evaluated stress-first (F, strain, D strain, P = R sigma, f_i = -V P grad N_i),
// which is algebraically the same as the 12x12 K but reads 10 doubles per element, not 144.
#include <memory>
#include <vector>

#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

enum class FeKind { linear, corotational };

class FiniteElementModel final : public ForceModel {
 public:
  /// One elasticity matrix per material; material_of_tet (empty = all material 0).
  FiniteElementModel(std::shared_ptr<const TetMesh> mesh, FeKind kind, std::vector<Mat6> materials, std::vector<std::uint16_t> material_of_tet = {});

  std::string_view name() const override;
  ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f) const override;
  double energy(std::span<const Vec3> x) const override;
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e) const override;

  /// Cauchy-like small-strain stress (Voigt, Pa) of element e at x, in the element's rotated
  /// frame for corotational (R^T sigma R is what is computed), unrotated for linear.
  Vec6 element_stress(std::span<const Vec3> x, std::size_t e) const;

 private:
  struct Element {
    Mat3 dm_inv;
    double volume = 0;
  };
  Mat3 deformation_gradient(std::span<const Vec3> x, std::size_t e) const;
  const Mat6& material(std::size_t e) const { return materials_[material_of_tet_.empty() ? 0 : material_of_tet_[e]]; }

  FeKind kind_;
  std::vector<Mat6> materials_;
  std::vector<std::uint16_t> material_of_tet_;
  std::vector<Element> elements_;
};

}  // namespace viscera::tissue
