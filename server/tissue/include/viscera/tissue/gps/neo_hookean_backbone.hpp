#pragma once  // SPDX-License-Identifier: Apache-2.0
// The large-strain GPS's elastic backbone (docs/TISSUE.md, "Large strain"): the stable neo-Hookean
// solid of Smith, de Goes and Kim (2018) on each tetrahedron,
//     Psi(F) = mu/2 (I_C - 3) + lam/2 (J - alpha)^2 - mu^2 / (2 lam),  alpha = 1 + mu / lam,
// with lam = lambda_Lame + mu, so that its stress linearises to 2 mu eps + lambda_Lame tr(eps) I:
// the material's own small-strain moduli. It stiffens in compression as rubber-like solids and soft
// tissues do (incompressible uniaxial: P = mu (s - 1/s^2)), its energy is zero and stress-free at
// rest, and it stays smooth and defined through inversion (J <= 0: no logarithm). F = Ds Dm^-1 with
// Ds, Dm the current and rest edge vectors from vertex 0; the energy is V0 Psi.
#include <array>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

struct NeoHookean {
  double mu = 0.0;  ///< shear modulus [Pa]
  double lam = 0.0;  ///< lambda_Lame + mu [Pa]
  double alpha() const { return 1.0 + mu / lam; }
};

/// The backbone of an isotropic elasticity D (Voigt, engineering shear); throws
/// std::invalid_argument naming what is not isotropic.
NeoHookean neo_hookean_of(const Mat6& D);

/// Dm^-1: the inverse of the rest edge vectors (x1 - x0, x2 - x0, x3 - x0) as columns.
Mat3 rest_shape_inverse(const std::array<Vec3, 4>& rest);

/// V0 Psi(F) [J].
double neo_hookean_energy(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0);
/// The vertex forces -d(V0 Psi)/dx [N], vertex by vertex.
Vec12 neo_hookean_forces(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0);
/// The tangent -df/dx (symmetric).
Mat12 neo_hookean_tangent(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0);

/// Viscoelasticity on the backbone: the memory variables filter its second Piola-Kirchhoff stress
/// S = F^-1 P = mu I + lam (J - alpha) cof(F)^T cof(F) / J (symmetric, invariant under rotation),
/// or where the bulk does not relax its deviatoric part DEV[S] = S - (S : C) C^-1 / 3
/// = mu (I - tr(C) C^-1 / 3) (the volume's stress removed exactly, whatever lam), kept in Voigt
/// order (xx, yy, zz, yz, xz, xy). The element's stress is P = P_e(F) + F W,
/// W = tau dq/dt - sum_l y_l zeta_l (3D quasi-linear viscoelasticity: at a held strain the stress
/// relaxes as the linear modulus does). Both are singular at J = 0: the memory takes J at least
/// kBackboneMemoryFloorJ (an element that inverted under a hand keeps finite memory).
inline constexpr double kBackboneMemoryFloorJ = 0.05;
inline constexpr std::array<std::array<int, 2>, 6> kVoigtPairs{{{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};
/// The tangent -df/dx of the stress F DEV[S] = mu (F - tr(C) cof(F) / (3 J)) (J floored as above).
Mat12 deviatoric_stress_tangent(const NeoHookean& m, const std::array<Vec3, 4>& x, const Mat3& dm_inv, double V0);
/// The tangent -df/dx of the stress -F H of a stress H held in the rest frame (f = V0 F H Dm^-T
/// on vertices 1-3): -V0 (g_v . H g_w) I for vertices v, w with F = sum_v x_v g_v^T.
Mat12 held_stress_tangent(const Mat3& held, const Mat3& dm_inv, double V0);

}  // namespace viscera::tissue
