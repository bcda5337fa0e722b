#pragma once  // SPDX-License-Identifier: Apache-2.0
// Writes simulation frames as ASCII VTU (ParaView) and a .pvd collection for time series.
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Point data: displacement [m] and velocity [m/s]; cell data: Green-Lagrange strain as a
/// symmetric tensor in ParaView's order (XX, YY, ZZ, XY, YZ, XZ) and its largest absolute
/// principal value. x and v may be empty (then the rest state is written).
void write_vtu(const std::string& path, const TetMesh& mesh, std::span<const Vec3> x, std::span<const Vec3> v);

/// Writes a ParaView collection listing (time [s], file) pairs; files relative to the .pvd.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& frames);

}  // namespace viscera::tissue
