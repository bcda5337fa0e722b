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

}  // namespace viscera::tissue
