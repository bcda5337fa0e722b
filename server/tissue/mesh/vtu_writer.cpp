#include "viscera/tissue/mesh/vtu_writer.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cstdio>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

using common::InputError;

namespace {
/// The file's text is built here and written by common::write_file_text (never through a link).
std::ostringstream text() {
  std::ostringstream out;
  out.precision(9);
  return out;
}
}  // namespace

void write_vtu(const std::string& path, const TetMesh& mesh, std::span<const Vec3> x, std::span<const Vec3> v) {
  const std::span<const Vec3> pos = x.empty() ? std::span<const Vec3>(mesh.nodes) : x;
  std::ostringstream out = text();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\""
      << mesh.nodes.size() << "\" NumberOfCells=\"" << mesh.tets.size() << "\">\n";
  out << "<PointData Vectors=\"displacement\">\n"
         "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const Vec3 u = pos[i] - mesh.nodes[i];
    out << u.x() << ' ' << u.y() << ' ' << u.z() << '\n';
  }
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const Vec3 w = v.empty() ? Vec3::Zero() : v[i];
    out << w.x() << ' ' << w.y() << ' ' << w.z() << '\n';
  }
  out << "</DataArray>\n</PointData>\n<CellData Tensors=\"green_strain\">\n"
         "<DataArray type=\"Float64\" Name=\"green_strain\" NumberOfComponents=\"6\" format=\"ascii\">\n";
  std::vector<double> principal(mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Tet& t = mesh.tets[e];
    const Mat3 dm = edge_matrix({mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]});
    const Mat3 ds = edge_matrix({pos[t[0]], pos[t[1]], pos[t[2]], pos[t[3]]});
    const Mat3 F = ds * dm.inverse();
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    out << E(0, 0) << ' ' << E(1, 1) << ' ' << E(2, 2) << ' ' << E(0, 1) << ' ' << E(1, 2) << ' ' << E(0, 2) << '\n';
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Mat3>(E, Eigen::EigenvaluesOnly).eigenvalues();
    principal[e] = ev.cwiseAbs().maxCoeff();
  }
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"max_principal_strain\" format=\"ascii\">\n";
  for (double p : principal) out << p << '\n';
  out << "</DataArray>\n</CellData>\n<Points>\n"
         "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const Vec3& p : pos) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const Tet& t : mesh.tets) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) out << 4 * (e + 1) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) out << "10\n";
  out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  common::write_file_text(path, out.str());
}

void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& frames) {
  std::ostringstream out = text();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, file] : frames) out << "<DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << file << "\"/>\n";
  out << "</Collection>\n</VTKFile>\n";
  common::write_file_text(path, out.str());
}

}  // namespace viscera::tissue
