#pragma once  // SPDX-License-Identifier: Apache-2.0
// The generalized particle system (the paper's Eq. (1), docs/MODEL.md section 1): every edge of a
// tetrahedron carries a tension that depends on all six edge elongations,
//     t = C dL,   C = diag(1/L0) H   (36 constants per tet, calibrated to linear FE),
// and pushes its ends with +t_e Y_e (vertex a) and -t_e Y_e (vertex b).
// Variants:
//  - paper:             t_e = (H dL)_e / L0_e  (the published form; not conservative at
//                       finite strain);
//  - energy_consistent: t_e = (H dL)_e / L_e, the exact gradient of E = 0.5 dL^T H dL.
// Optional signed-volume term E_V = 0.5 kappa V0 (V/V0 - 1)^2 (kappa = fraction x Reuss bulk
// modulus): restores inverted elements, which the edge lengths alone cannot see. H is calibrated
// with the term's small-strain stiffness removed, so the sum still equals linear FE there.
#include <memory>
#include <vector>

#include "viscera/tissue/gps/gps_mechanisms.hpp"
#include "viscera/tissue/gps/neo_hookean_backbone.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

enum class GpsVariant { paper, energy_consistent };

struct GpsOptions {
  GpsVariant variant = GpsVariant::paper;
  /// kappa / (Reuss bulk modulus) of the signed-volume term, in [0, 1); 0 disables it.
  double volume_stiffness_fraction = 0.0;
  /// Viscous part, stiffening, asymmetry and softening (gps_mechanisms.hpp).
  GpsMechanisms mechanisms;
  /// The large-strain GPS (docs/TISSUE.md, "Large strain"): the elastic response is the stable
  /// neo-Hookean solid of the material's moduli (gps/neo_hookean_backbone.hpp), and the edges carry
  /// what the edge map's stiffening adds to the linear edge response 0.5 dL^T H dL:
  /// E = E_GPS - 0.5 dL^T H dL + V0 Psi(F). At small strain the two edge terms cancel and the
  /// backbone is linear FE, so the sum is the GPS's as before. Its memory variables relax the
  /// backbone's stress (neo_hookean_backbone.hpp), not the edges'. Needs the energy-consistent
  /// variant, no volume term (the backbone holds the volume), isotropic materials and the edge-map
  /// form of the stiffening; takes viscoelasticity (the bulk relaxing as the shear or not at all)
  /// or stiffening, not both, and no first-load softening.
  bool large_strain = false;
};

class GpsModel final : public ForceModel {
 public:
  GpsModel(std::shared_ptr<const TetMesh> mesh, std::vector<Mat6> materials, std::vector<std::uint16_t> material_of_tet = {},
           GpsOptions options = {});

  std::string_view name() const override;
  ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f) const override;
  ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory) const override;
  /// Parts are contiguous ranges of blocks (kLanes elements each).
  ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory, ElementPart part) const override;
  std::pair<std::size_t, std::size_t> part_elements(ElementPart part) const override;
  std::size_t memory_size() const override;
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s) const override;
  /// With first-load softening the tangent depends on each edge's extremes in `memory`.
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s, std::span<const double> memory) const override;
  double stiffness_damping_time_s() const override { return options_.mechanisms.viscous.kelvin_voigt_time_s; }
  /// From the edge map h (gps/fung_map.hpp): the tangent of a tetrahedron holds h'_i H_ij h'_j and
  /// h''_i (H h)_i, so it grows at most by max(h'^2 + |h h''|) over |e| <= edge_strain, against
  /// h'(0)^2 at rest.
  double stiffness_growth(double edge_strain) const override;
  double energy(std::span<const Vec3> x) const override;
  /// Element e's elastic energy [J] with its own constants and rest lengths, on the vertices `t`:
  /// its own (element(e)) or, between a cut of the mesh and follow_edit, its vertices before the
  /// cut (MeshEdit::replaced), whose rest positions the cut left as they were.
  double element_energy(std::span<const Vec3> x, std::size_t e, const Tet& t) const;
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e) const override;

  const GpsOptions& options() const { return options_; }
  /// Memory for this model's elements from the memory of `before` (a model of the same options on
  /// the mesh this one's was cut from): element e starts in the state of element origin[e] of
  /// `before`. Edge quantities go through the parent's small strain, which its six elongations
  /// determine (dL_k = L0_k n_k' eps n_k), so a child carries its parent's viscoelastic state; a
  /// child's first-load extremes are the largest of its parent's, in each sense.
  std::vector<double> memory_from(const GpsModel& before, std::span<const double> memory, std::span<const std::int32_t> origin) const;

  /// Follows an edit of the mesh this model holds (done by its owner, e.g. a MeshCutter on the
  /// same TetMesh): the changed and the new elements are calibrated from their own rest shapes
  /// with their parent's material, the others stay bit for bit. `memory` (State::memory) is
  /// brought to the new layout in place, changed and new elements carrying their parent's state
  /// as memory_from does; empty memory (a relaxed organ) stays empty. Cost: the changed elements
  /// (vectors grow geometrically).
  void follow_edit(const MeshEdit& edit, std::vector<double>& memory);
  /// Room for this many elements, so that following edits up to it never reallocates (a
  /// reallocation copies every element: milliseconds at 12k). Reserve the memory alike with
  /// memory_size_for().
  void reserve_elements(std::size_t elements);
  /// The memory a model of this many elements keeps (doubles).
  std::size_t memory_size_for(std::size_t elements) const;
  /// The paper's 36 constants C = diag(1/L0) H of element e (the volume term excluded).
  Mat6 paper_constants(std::size_t e) const;
  /// The large-strain GPS's backbone of element e, its Dm^-1 and rest volume.
  NeoHookean backbone(std::size_t e) const { return backbone_[material_of(e)]; }
  /// H of element e (symmetric 6x6) as used by the model.
  Mat6 edge_hessian(std::size_t e) const;
  /// Element e's index into the materials (0 without per-element materials).
  std::size_t material_of(std::size_t e) const;

  /// The hot loop's data: tetrahedra in blocks of kLanes, structure-of-arrays inside a block, so
  /// that one block streams contiguously and every arithmetic line vectorises across the lanes.
  static constexpr int kLanes = 8;
  struct Block {
    std::int32_t v[4][kLanes];
    double rest_length[6][kLanes];
    double inv_rest_length[6][kLanes];
    double H[21][kLanes];  ///< upper triangle of H, row by row
    double rest_volume[kLanes];
    double kappa[kLanes];  ///< signed-volume stiffness [Pa] (0 when the term is off)
  };

  /// Per block, for the large-strain GPS: each lane's backbone (padding lanes: all zero).
  struct NeoBlock {
    double dm_inv[9][kLanes];  ///< Dm^-1, row by row
    double mu[kLanes], lam[kLanes], alpha[kLanes];
  };

  /// Per block, for bulk weights that differ from the shear weights: H_vol = s hv hv^T.
  struct BulkBlock {
    double hv[6][kLanes];
    double scale[kLanes];  ///< (K_Reuss - kappa) / V0 [Pa/m^3]
  };

 private:
  /// The blocks [first, last) of a part.
  std::pair<std::size_t, std::size_t> part_blocks(ElementPart part) const;
  template <bool kEnergyConsistent, bool kVolume, bool kMemory>
  ForceStats add_forces_impl(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate* memory, std::size_t first_block,
                             std::size_t end_block) const;
  /// phi, dphi_de: first-load softening factors per edge and their derivatives in the edge strain.
  /// held: the part of the edge tensions (before the 1/L scaling) that the step's start holds, the
  /// same for every x of the step (the memory variables' and the Kelvin-Voigt rate's share of the
  /// previous elongations): it adds to the geometric stiffness only.
  Mat12 tangent(std::span<const Vec3> x, std::size_t e, double stiffness_scale, double bulk_extra, const Vec6* phi = nullptr,
                const Vec6* dphi_de = nullptr, const Vec6* held = nullptr) const;
  /// The large-strain GPS's tangent over a viscoelastic step of dt: scale (1 - sum y_l c_l + tau /
  /// dt) times the backbone's, plus the held stress's (the memory at the step's start, if given).
  Mat12 backbone_tangent(std::span<const Vec3> x, std::size_t e, double dt_s, double scale, std::span<const double> memory) const;
  /// Offset of the softening extremes in a block's memory (tension extremes, then compression).
  std::size_t softening_offset() const { return (1 + mechanisms_) * 6 * kLanes; }
  std::size_t memory_stride() const { return (1 + mechanisms_ + (options_.mechanisms.softening.active() ? 2 : 0)) * 6 * kLanes; }
  Mat6 packed_hessian(std::size_t e) const;
  /// H of a tet of material m with these rest positions, as the model uses it.
  Mat6 calibrated_hessian(const std::array<Vec3, 4>& rest, std::size_t m) const;
  /// Writes block lane `slot` from the mesh (a padding lane past the last element: a copy of its
  /// block's first element with H = 0).
  void write_lane(std::size_t slot);
  /// Element memory of a child (at `to`) from its parent's (at `in`): edge vectors through the
  /// strain, extremes as the parent's largest. Strided by kLanes.
  void carry_memory(const double* in, const std::array<Vec3, 4>& parent_rest, const Mat6& parent_h, double* to, std::size_t e) const;
  double edge_length(std::size_t e, int k) const;

  GpsOptions options_;
  bool with_volume_ = false;
  std::vector<Block> blocks_;  ///< padding lanes have H = 0 and copy a real element
  std::vector<BulkBlock> bulk_;  ///< only when bulk and shear relax differently
  std::vector<NeoBlock> neo_;  ///< only for the large-strain GPS
  bool deviatoric_memory_ = false;  ///< the large-strain GPS's memory: DEV[S] (the bulk does not relax), else S
  std::vector<NeoHookean> backbone_;  ///< per material, for the large-strain GPS
  std::size_t mechanisms_ = 0;
  std::vector<Mat6> materials_;
  std::vector<std::uint16_t> material_of_tet_;  ///< empty: all material 0
  std::vector<double> kappa_;  ///< signed-volume stiffness per material [Pa]
};

}  // namespace viscera::tissue
