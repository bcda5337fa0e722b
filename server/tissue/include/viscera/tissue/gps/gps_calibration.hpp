#pragma once  // SPDX-License-Identifier: Apache-2.0
// Calibration of the generalized particle system's 36 constants per tetrahedron from linear FE
// (docs/MODEL.md section 1; the paper, section 3). Edge tensions t = C dL with C = diag(1/L0) H.
#include <array>

#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

/// H of K_fe = J^T H J, by the pseudo-inverse route: H = (J^+)^T K_fe J^+. Symmetric 6x6.
Mat6 gps_edge_hessian(const std::array<Eigen::Vector3d, 4>& rest, const Mat6& D);

/// The paper's C = diag(1/L0) H by the pseudo-inverse route.
Mat6 calibrate_gps_pseudoinverse(const std::array<Eigen::Vector3d, 4>& rest, const Mat6& D);

/// The paper's own route: six displacement modes that each change the length of exactly one edge
/// (and contain no rigid motion); their linear FE forces are matched in the least-squares sense
/// by the edge-vector basis of Eq. (1): 12 equations for the 6 constants of each mode.
Mat6 calibrate_gps_edge_modes(const std::array<Eigen::Vector3d, 4>& rest, const Mat6& D);

/// h with J^T h = grad V (the signed volume's gradient expressed in edge elongations), so that a
/// volume energy 0.5 (kappa/V0) dV^2 equals 0.5 (kappa/V0) (h . dL)^2 at small strain.
Vec6 volume_in_elongations(const std::array<Eigen::Vector3d, 4>& rest);

}  // namespace viscera::tissue
