#pragma once  // SPDX-License-Identifier: Apache-2.0
// Rotation part of the polar decomposition F = R S (R a proper rotation, S symmetric), used by
// corotational FE.
#include <Eigen/Core>

namespace viscera::tissue {

/// R of F = R S. For det F > 0: Higham's scaled Newton iteration (quadratic convergence, about
/// 4-6 iterations from a typical tissue deformation). For det F <= 0 (inverted element): from the
/// SVD with the smallest singular direction flipped, so that R stays a proper rotation
/// (Irving et al. 2004).
Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F);

}  // namespace viscera::tissue
