#pragma once  // SPDX-License-Identifier: Apache-2.0
// Linear elasticity matrices D (6x6, Voigt order xx yy zz yz xz xy, engineering shear),
// the material input of every model. Moduli in pascals.
#include <string>

#include <Eigen/Core>

#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

struct IsotropicElasticity {
  double youngs_modulus_pa = 0.0;
  double poisson_ratio = 0.0;
};

/// Transversely isotropic: isotropic in the plane normal to the fibre direction.
/// Five constants: in-plane E_p, nu_p; along the fibre E_f; nu_fp (contraction in the plane
/// under fibre-direction stress, nu_fp = -eps_p / eps_f); shear modulus G_f of planes that
/// contain the fibre.
struct TransverselyIsotropicElasticity {
  double plane_youngs_modulus_pa = 0.0;
  double plane_poisson_ratio = 0.0;
  double fibre_youngs_modulus_pa = 0.0;
  double fibre_plane_poisson_ratio = 0.0;
  double fibre_shear_modulus_pa = 0.0;
  Eigen::Vector3d fibre_direction = Eigen::Vector3d::UnitZ();
};

/// D of an isotropic material. Throws InputError (field named) for E <= 0 or nu outside
/// (-1, 0.5).
Mat6 elasticity_matrix(const IsotropicElasticity& m, const std::string& source = "material");

/// D of a transversely isotropic material, rotated so its axis is the fibre direction.
/// Throws InputError when a constant is out of range or D is not positive definite.
Mat6 elasticity_matrix(const TransverselyIsotropicElasticity& m, const std::string& source = "material");

/// Checks that D is symmetric positive definite; throws InputError naming `source` if not.
void check_elasticity_matrix(const Mat6& D, const std::string& source);

/// Voigt-order rotation of an elasticity matrix: D' for the frame rotated by R (x' = R x).
Mat6 rotate_elasticity(const Mat6& D, const Mat3& R);

/// Reuss bulk modulus 1 / (m^T D^-1 m), m = (1,1,1,0,0,0): the largest kappa for which
/// D - kappa m m^T stays positive semi-definite.
double reuss_bulk_modulus(const Mat6& D);

/// Largest P-wave modulus (sets the explicit stable step): max eigenvalue of D.
double max_wave_modulus(const Mat6& D);

}  // namespace viscera::tissue
