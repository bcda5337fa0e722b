#include "label_mesher.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <unordered_map>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/make_mesh_3.h>
#include <Eigen/Geometry>

namespace viscera::meshing {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<K>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

constexpr int kPad = 2;  // background voxels around the organ: a crop plane closes like any other boundary

}  // namespace

LabelledMesh mesh_labels(const LabelMap& map, const LabelMeshRequest& request) {
  // Labels become 1..n in an 8-bit image cropped to the organ (and padded): CGAL's word types, and
  // a small image to search.
  std::unordered_map<std::int32_t, std::uint8_t> index;
  for (std::size_t k = 0; k < request.labels.size(); ++k) index[request.labels[k]] = static_cast<std::uint8_t>(k + 1);
  std::array<int, 3> lo{map.dims[0], map.dims[1], map.dims[2]}, hi{-1, -1, -1};
  for (int k = 0; k < map.dims[2]; ++k)
    for (int j = 0; j < map.dims[1]; ++j)
      for (int i = 0; i < map.dims[0]; ++i)
        if (index.count(map.at(i, j, k))) {
          const int ijk[3] = {i, j, k};
          for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], ijk[a]), hi[a] = std::max(hi[a], ijk[a]);
        }
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) {
    lo[a] -= kPad;
    n[a] = hi[a] - lo[a] + 1 + kPad;
  }
  // The image in voxel units: CGAL's image is axis-aligned; the affine (rotation, flips, spacing)
  // is applied to the nodes afterwards. Anisotropic voxels are meshed in millimetres along each axis.
  const Eigen::Vector3d v = map.spacing_m() * 1e3;
  _image* im = ::_createImage(n[0], n[1], n[2], 1, v[0], v[1], v[2], 1, WK_FIXED, SGN_UNSIGNED);
  im->tx = static_cast<float>(lo[0] * v[0]);
  im->ty = static_cast<float>(lo[1] * v[1]);
  im->tz = static_cast<float>(lo[2] * v[2]);
  auto* data = static_cast<std::uint8_t*>(im->data);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int si = i + lo[0], sj = j + lo[1], sk = k + lo[2];
        std::uint8_t value = 0;
        if (si >= 0 && sj >= 0 && sk >= 0 && si < map.dims[0] && sj < map.dims[1] && sk < map.dims[2]) {
          const auto it = index.find(map.at(si, sj, sk));
          if (it != index.end()) value = it->second;
        }
        data[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] = value;
      }
  CGAL::Image_3 image(im);

  CGAL::get_default_random() = CGAL::Random(request.seed);
  CGAL::Random rng(request.seed);
  namespace p = CGAL::parameters;
  const Domain domain = Domain::create_labeled_image_mesh_domain(image, p::relative_error_bound = 1e-6, p::p_rng = &rng);
  const double size_mm = request.edge_m * 1e3;
  const Criteria criteria(p::facet_angle = 25, p::facet_size = size_mm, p::facet_distance = request.facet_distance_m * 1e3,
                          p::cell_radius_edge_ratio = 3, p::cell_size = size_mm);
  // No time limits: CGAL's default stops perturbation and exudation after as long as the refinement
  // took, which makes the mesh depend on how busy the machine is (seen: 11,696 and 11,692 tetrahedra).
  const auto perturb = p::perturb(p::time_limit = 0, p::sliver_bound = request.sliver_bound_deg);
  const auto exude = p::exude(p::time_limit = 0, p::sliver_bound = request.sliver_bound_deg);
  const C3t3 c3t3 = request.optimize ? CGAL::make_mesh_3<C3t3>(domain, criteria, perturb, exude, p::no_lloyd(), p::odt(p::max_iteration_number = 20))
                                     : CGAL::make_mesh_3<C3t3>(domain, criteria, perturb, exude, p::no_lloyd(), p::no_odt());

  // The complex's tetrahedra and the nodes they use, in the patient's space.
  LabelledMesh out;
  std::unordered_map<const void*, std::int32_t> node_of;
  const Eigen::Matrix3d lin = map.affine.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = map.affine.topRightCorner<3, 1>();
  const auto node = [&](Tr::Vertex_handle vh) {
    const auto [it, inserted] = node_of.emplace(&*vh, static_cast<std::int32_t>(out.nodes.size()));
    if (inserted) {
      const auto& pt = vh->point().point();
      const Eigen::Vector3d q(pt.x() / v[0], pt.y() / v[1], pt.z() / v[2]);  // voxel index coordinates
      out.nodes.push_back(lin * q + shift);
    }
    return it->second;
  };
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    std::array<std::int32_t, 4> t{};
    for (int k = 0; k < 4; ++k) t[k] = node(c->vertex(k));
    const Eigen::Vector3d& a = out.nodes[t[0]];
    if ((out.nodes[t[1]] - a).dot((out.nodes[t[2]] - a).cross(out.nodes[t[3]] - a)) < 0) std::swap(t[2], t[3]);  // a flipping affine
    out.tets.push_back(t);
    out.label.push_back(request.labels[static_cast<std::size_t>(c3t3.subdomain_index(c)) - 1]);
  }
  return out;
}

}  // namespace viscera::meshing
