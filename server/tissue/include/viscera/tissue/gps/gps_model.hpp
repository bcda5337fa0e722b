#pragma once
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

#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

enum class GpsVariant { paper, energy_consistent };

/// Viscoelasticity of the GPS (docs/MODEL.md section 3). With memory variables the elasticity matrices
/// given to the model are the UNRELAXED ones; every tetrahedron keeps per mechanism a 6-vector
/// zeta_l of filtered edge elongations (d zeta_l / dt = w_l (dL - zeta_l), updated exactly), and
/// the tension becomes t = S [H_dev (dL - sum Y^s_l zeta_l) + H_vol (dL - sum Y^b_l zeta_l)].
/// Shear and bulk share the relaxation frequencies and have their own weights (their own Q).
struct GpsViscoelasticity {
  std::vector<double> omega_rad_s;  ///< relaxation frequencies w_l
  std::vector<double> shear_weight;  ///< Y^s_l
  std::vector<double> bulk_weight;  ///< Y^b_l (same size; zeros: no bulk relaxation)
  /// Kelvin-Voigt baseline: t += S H tau d(dL)/dt (one relaxation time; 0 = off).
  double kelvin_voigt_time_s = 0.0;
  /// Fung's quasi-linear viscoelasticity: each edge strain e = dL/L0 is replaced by
  /// (exp(B e) - 1) / B before the elastic and relaxation response (B = 0: linear).
  double qlv_stiffening = 0.0;
  /// How the stiffening enters (gps/fung_map.hpp): edge_map, the published form above (exact in
  /// 1D, not conservative in 3D: its tangent is not symmetric, and Newton stalls on a stretched
  /// specimen near B e = 1); or energy, the elastic energy 0.5 h^T H h of the energy map h
  /// (h h' = the edge map, so a bar responds alike), tensions t_k = h'(e_k) (H (h - memory))_k.
  enum class QlvForm { edge_map, energy } qlv_form = QlvForm::edge_map;
  /// Tension/compression asymmetry (energy form only): compressed edges respond r times as stiff
  /// (gps/fung_map.hpp, edge_energy_map); 1 = symmetric.
  double compression_ratio = 1.0;
  /// Whether the elastic energy is 0.5 h^T H h with a nonlinear edge map (energy form).
  bool energy_map() const { return qlv_form == QlvForm::energy && (qlv_stiffening > 0 || compression_ratio != 1.0); }
  /// First-load softening d in [0, 1) (Ogden-Roxburgh-like, per edge): below the largest strain an
  /// edge has seen in the same sense (tension or compression), m, its elastic response (the mapped
  /// elongation, or in the energy form its elastic tension) is scaled by 1 - d (1 - |e| / m); at or
  /// beyond m it is the virgin response. The two extremes per edge are kept with the memory.
  /// Under proportional loading every edge's |e| / m is the specimen's, so a homogeneous specimen
  /// softens exactly as the lab's 1D law.
  double first_load_softening = 0.0;

  bool has_memory() const { return !omega_rad_s.empty() || kelvin_voigt_time_s > 0 || first_load_softening > 0; }
};

struct GpsOptions {
  GpsVariant variant = GpsVariant::paper;
  /// kappa / (Reuss bulk modulus) of the signed-volume term, in [0, 1); 0 disables it.
  double volume_stiffness_fraction = 0.0;
  GpsViscoelasticity viscoelasticity;
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
  std::size_t memory_size() const override;
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s) const override;
  /// With first-load softening the tangent depends on each edge's extremes in `memory`.
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s, std::span<const double> memory) const override;
  double stiffness_damping_time_s() const override { return options_.viscoelasticity.kelvin_voigt_time_s; }
  double energy(std::span<const Vec3> x) const override;
  Mat12 element_tangent(std::span<const Vec3> x, std::size_t e) const override;

  const GpsOptions& options() const { return options_; }
  /// The paper's 36 constants C = diag(1/L0) H of element e (the volume term excluded).
  Mat6 paper_constants(std::size_t e) const;
  /// H of element e (symmetric 6x6) as used by the model.
  Mat6 edge_hessian(std::size_t e) const;

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

  /// Per block, for bulk weights that differ from the shear weights: H_vol = s hv hv^T.
  struct BulkBlock {
    double hv[6][kLanes];
    double scale[kLanes];  ///< (K_Reuss - kappa) / V0 [Pa/m^3]
  };

 private:
  template <bool kEnergyConsistent, bool kVolume, bool kMemory>
  ForceStats add_forces_impl(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate* memory, std::size_t first_block,
                             std::size_t end_block) const;
  /// phi, dphi_de: first-load softening factors per edge and their derivatives in the edge strain.
  Mat12 tangent(std::span<const Vec3> x, std::size_t e, double stiffness_scale, double bulk_extra, const Vec6* phi = nullptr,
                const Vec6* dphi_de = nullptr) const;
  /// Offset of the softening extremes in a block's memory (tension extremes, then compression).
  std::size_t softening_offset() const { return (1 + mechanisms_) * 6 * kLanes; }
  std::size_t memory_stride() const { return (1 + mechanisms_ + (options_.viscoelasticity.first_load_softening > 0 ? 2 : 0)) * 6 * kLanes; }
  Mat6 packed_hessian(std::size_t e) const;
  double edge_length(std::size_t e, int k) const;

  GpsOptions options_;
  bool with_volume_ = false;
  std::vector<Block> blocks_;  ///< padding lanes have H = 0 and copy a real element
  std::vector<BulkBlock> bulk_;  ///< only when bulk and shear relax differently
  std::size_t mechanisms_ = 0;
};

}  // namespace viscera::tissue
