#pragma once  // SPDX-License-Identifier: Apache-2.0
// The tissue's strain at a length scale, for trainers' damage limits (docs/TRAINING.md, "Tissue
// strain at the instrument"). The largest edge strain |L - L0| / L0 of any one tetrahedron
// depends on the mesh: a finer mesh resolves the peak under a probe that a coarse one spreads
// over its large elements (0.59 on the 12k liver against 0.30 on the 1.5k liver under the same
// press), and an edge only sees the strain along its own direction. Here each tetrahedron's strain
// is the largest departure from 1 of its principal stretches, max |sqrt(1 + 2 e_i) - 1| over the
// eigenvalues e_i of its Green-Lagrange strain E = (G + G^T + G^T G) / 2 (G = dU/dX, its
// displacement gradient, from displacements so that small strains keep their digits): for a
// uniform deformation the same on any mesh, and the edge strain of an edge along the principal
// direction. That strain is averaged over the tissue within a radius of a point of the rest
// shape: volume-weighted over the tetrahedra whose rest centroids lie in the ball (the nearest one
// if none does), as nonlocal damage models average their equivalent strain. The scalar is
// averaged, not the tensor: under a dent the strain's sign turns about the dent's centre, and the
// tensor's average there kept a tenth of the strain (ball_strain_test).
//
// It follows the mesh it was made for as that mesh is cut (follow_edit): the elements an edit
// changed or added are kept apart from the grid and looked at on every query.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

/// Largest |sqrt(1 + 2 e_i) - 1| over the eigenvalues e_i of a Green-Lagrange strain (an
/// eigenvalue below -1/2, which no deformation gives, counts as a stretch of 0).
double principal_stretch_strain(const Mat3& green);

class BallStrain {
 public:
  /// `rest`: the mesh the positions belong to (read at each query: a cut grows it in place).
  BallStrain(std::shared_ptr<const TetMesh> rest, double radius_m);

  double radius_m() const { return radius_; }

  struct Result {
    double strain = 0.0;  ///< the volume-weighted average of the elements' principal_stretch_strain
    std::size_t elements = 0;  ///< tetrahedra averaged over
    double volume_m3 = 0.0;  ///< their rest volume
  };
  /// The strain of the tissue within the radius of `rest_point` (a point of the rest shape), the
  /// organ at positions x.
  Result at(std::span<const Vec3> x, const Vec3& rest_point) const;

  /// The elements whose rest centroids lie within the radius of `rest_point` (ascending), or the
  /// one nearest to it when none does, into `out`.
  void elements_near(const Vec3& rest_point, std::vector<std::size_t>& out) const;

  /// A share of a ball's average: the volume-weighted sum of the strains of elements[k] for k =
  /// first, first + stride, ..., and their volume (a server spreads one ball over several ticks).
  struct Sum {
    double strain_volume_m3 = 0.0, volume_m3 = 0.0;
  };
  Sum sum_over(std::span<const Vec3> x, std::span<const std::size_t> elements, std::size_t first, std::size_t stride) const;

  /// The mesh was cut (MeshEdit): the replaced and the new elements are looked at apart.
  void follow_edit(const MeshEdit& edit);

 private:
  void describe(std::size_t e);
  template <class Visit>
  void visit_near(const Vec3& p, Visit&& visit) const;

  std::shared_ptr<const TetMesh> rest_;
  double radius_;
  // Per element: Dm^-1 and rest volume and centroid.
  std::vector<Mat3> dm_inv_;
  std::vector<double> volume_;
  std::vector<Vec3> centroid_;
  // A uniform grid of cells (edge cell_) over the centroids as built; cell c holds
  // grid_elements_[grid_start_[c] .. grid_start_[c + 1]).
  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1.0;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::uint32_t> grid_start_, grid_elements_;
  std::vector<std::uint8_t> moved_;  ///< per element: changed by an edit since the grid was built
  std::vector<std::uint32_t> loose_;  ///< the elements changed or added since: always looked at
};

}  // namespace viscera::tissue
