#pragma once  // SPDX-License-Identifier: Apache-2.0
// What a GPS model is composed of beyond its linear elastic law (docs/MODEL.md sections 1-3):
// four independent parts, each with its own validity rule, and the two rules between them.
//
//   viscous      memory variables (constant Q) and a Kelvin-Voigt rate term
//   stiffening   Fung's nonlinear map of each edge strain, in the published or the energy form
//   asymmetry    compressed edges stiffer than stretched ones (energy form only)
//   softening    first-load (Ogden-Roxburgh-like) softening per edge
//
// An empty part is off; GpsMechanisms{} is the linear elastic GPS.
#include <cstddef>
#include <vector>

#include "viscera/tissue/gps/fung_map.hpp"

namespace viscera::tissue {

/// Every tetrahedron keeps per mechanism a 6-vector zeta_l of filtered edge elongations
/// (d zeta_l / dt = w_l (dL - zeta_l), updated exactly); the tension becomes
/// t = S [H_dev (dL - sum Y^s_l zeta_l) + H_vol (dL - sum Y^b_l zeta_l)]. The elasticity given to
/// the model is then the UNRELAXED one. Shear and bulk share the frequencies, each with its weights.
struct GpsViscous {
  std::vector<double> omega_rad_s;  ///< relaxation frequencies w_l (at most kMaxMechanisms)
  std::vector<double> shear_weight;  ///< Y^s_l, one per frequency
  std::vector<double> bulk_weight;  ///< Y^b_l, one per frequency; empty: as the shear
  /// Kelvin-Voigt: t += S H tau d(dL)/dt (one relaxation time tau; 0 = off).
  double kelvin_voigt_time_s = 0.0;

  static constexpr std::size_t kMaxMechanisms = 8;
  std::size_t mechanisms() const { return omega_rad_s.size(); }
  bool bulk_differs() const { return !bulk_weight.empty() && bulk_weight != shear_weight; }
  double bulk(std::size_t l) const { return bulk_weight.empty() ? shear_weight[l] : bulk_weight[l]; }
  bool active() const { return !omega_rad_s.empty() || kelvin_voigt_time_s > 0; }
  /// Throws std::invalid_argument naming the rule broken.
  void validate() const;
};

/// Fung's quasi-linear viscoelasticity: each edge strain e = dL / L0 is replaced by
/// (exp(B e) - 1) / B before the elastic and relaxation response (B = 0: linear).
struct GpsStiffening {
  double b = 0.0;
  /// edge_map: the published form above (exact in 1D, not conservative in 3D: its tangent is not
  /// symmetric, and Newton stalls on a stretched specimen near B e = 1); energy: the elastic energy
  /// 0.5 h^T H h of the energy map h (h h' = the edge map, so a bar responds alike), tensions
  /// t_k = h'(e_k) (H (h - memory))_k (gps/fung_map.hpp).
  enum class Form { edge_map, energy } form = Form::edge_map;
  /// The law g(e) (gps/fung_map.hpp): Fung's exponential, or an odd shape (energy form only).
  StiffeningShape shape = StiffeningShape::exponential;

  bool active() const { return b > 0; }
  void validate() const;
};

/// Compressed edges respond r times as stiff as stretched ones (gps/fung_map.hpp, edge_energy_map).
struct GpsAsymmetry {
  double compression_ratio = 1.0;

  bool active() const { return compression_ratio != 1.0; }
  void validate() const;
};

/// First-load softening d in [0, 1), per edge: below the largest strain an edge has seen in the
/// same sense (tension or compression), m, its elastic response (the mapped elongation, or in the
/// energy form its elastic tension) is scaled by 1 - d (1 - |e| / m); at or beyond m it is the
/// virgin response. The two extremes per edge are kept with the memory. Under proportional loading
/// every edge's |e| / m is the specimen's, so a homogeneous specimen softens as the 1D law.
struct GpsSoftening {
  double d = 0.0;

  bool active() const { return d > 0; }
  void validate() const;
};

struct GpsMechanisms {
  GpsViscous viscous;
  GpsStiffening stiffening;
  GpsAsymmetry asymmetry;
  GpsSoftening softening;

  /// Whether the elastic energy is 0.5 h^T H h with a nonlinear edge map (the energy form).
  bool energy_map() const { return stiffening.form == GpsStiffening::Form::energy && (stiffening.active() || asymmetry.active()); }
  /// Whether elements keep state between steps (the model's memory).
  bool has_memory() const { return viscous.active() || softening.active(); }
  /// How many times stiffer than at rest an edge's response is at edge strains up to |edge_strain|
  /// (>= 1): the growth of the stiffening and the asymmetry (GpsModel::stiffness_growth).
  double stiffness_growth(double edge_strain) const;
  /// Each part's rule, then the rules between parts: the asymmetry lives in the energy form only,
  /// and the energy form relaxes the whole elastic tension, so bulk and shear must relax alike.
  void validate() const;
};

}  // namespace viscera::tissue
