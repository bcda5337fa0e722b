#include "viscera/tissue/mesh/locality_order.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <array>
#include <numeric>

namespace viscera::tissue {

namespace {

constexpr int kBits = 21;  // per axis: 3 x 21 bits fill a 63-bit key

/// The position of cell `c` (each coordinate below 2^kBits) along a 3D Hilbert curve: Skilling's
/// transform of the coordinates into the curve's "transposed" index, whose bits are then
/// interleaved (J. Skilling, Programming the Hilbert curve, AIP Conf. Proc. 707, 2004).
std::uint64_t hilbert_key(std::array<std::uint32_t, 3> c) {
  const std::uint32_t top = 1u << (kBits - 1);
  for (std::uint32_t q = top; q > 1; q >>= 1) {
    const std::uint32_t below = q - 1;
    for (int i = 0; i < 3; ++i) {
      if (c[i] & q) {
        c[0] ^= below;  // invert the low bits of the first axis
      } else {
        const std::uint32_t swap = (c[0] ^ c[i]) & below;  // exchange the low bits with the first axis
        c[0] ^= swap;
        c[i] ^= swap;
      }
    }
  }
  for (int i = 1; i < 3; ++i) c[i] ^= c[i - 1];  // Gray code
  std::uint32_t flip = 0;
  for (std::uint32_t q = top; q > 1; q >>= 1)
    if (c[2] & q) flip ^= q - 1;
  for (auto& v : c) v ^= flip;
  std::uint64_t key = 0;
  for (int b = kBits - 1; b >= 0; --b)
    for (int i = 0; i < 3; ++i) key = (key << 1) | ((c[i] >> b) & 1u);
  return key;
}

}  // namespace

TetMesh ordered_for_locality(const TetMesh& mesh, Renumbering* renumbering) {
  const std::size_t nt = mesh.tet_count(), nn = mesh.node_count();
  TetMesh out;
  out.source = mesh.source;
  // Centroids on a 2^21 grid over the bounding box (its longest side, so cells are cubes).
  std::vector<std::uint64_t> key(nt, 0);
  if (nt > 0) {
    const Box box = bounding_box(mesh);
    const double side = std::max((box.hi - box.lo).maxCoeff(), 1e-300);
    const double cells = static_cast<double>((1u << kBits) - 1);
    for (std::size_t e = 0; e < nt; ++e) {
      Vec3 centroid = Vec3::Zero();
      for (const std::int32_t v : mesh.tets[e]) centroid += mesh.nodes[static_cast<std::size_t>(v)];
      const Vec3 unit = ((0.25 * centroid - box.lo) / side).cwiseMax(0.0).cwiseMin(1.0);
      std::array<std::uint32_t, 3> cell{};
      for (int i = 0; i < 3; ++i) cell[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(unit[i] * cells);
      key[e] = hilbert_key(cell);
    }
  }
  std::vector<std::int32_t> old_tet(nt);
  std::iota(old_tet.begin(), old_tet.end(), 0);
  std::stable_sort(old_tet.begin(), old_tet.end(),
                   [&](std::int32_t a, std::int32_t b) { return key[static_cast<std::size_t>(a)] < key[static_cast<std::size_t>(b)]; });
  // Nodes in the order the reordered tetrahedra last name them, then the unnamed ones: walking the
  // tetrahedra from the end, each node takes the highest number left when first met.
  std::vector<char> named(nn, 0);
  for (const Tet& t : mesh.tets)
    for (const std::int32_t v : t) named[static_cast<std::size_t>(v)] = 1;
  const auto named_count = static_cast<std::int32_t>(std::count(named.begin(), named.end(), 1));
  std::vector<std::int32_t> new_node(nn, -1), old_node(nn, -1);
  std::int32_t next = named_count;
  for (auto e = old_tet.rbegin(); e != old_tet.rend(); ++e) {
    const Tet& t = mesh.tets[static_cast<std::size_t>(*e)];
    for (auto v = t.rbegin(); v != t.rend(); ++v)
      if (new_node[static_cast<std::size_t>(*v)] < 0) {
        new_node[static_cast<std::size_t>(*v)] = --next;
        old_node[static_cast<std::size_t>(next)] = *v;
      }
  }
  next = named_count;
  for (std::size_t v = 0; v < nn; ++v)
    if (!named[v]) {
      new_node[v] = next;
      old_node[static_cast<std::size_t>(next++)] = static_cast<std::int32_t>(v);
    }
  out.nodes.resize(nn);
  for (std::size_t v = 0; v < nn; ++v) out.nodes[v] = mesh.nodes[static_cast<std::size_t>(old_node[v])];
  out.tets.resize(nt);
  std::vector<std::int32_t> new_tet(nt);
  for (std::size_t e = 0; e < nt; ++e) {
    const Tet& t = mesh.tets[static_cast<std::size_t>(old_tet[e])];
    for (int k = 0; k < 4; ++k) out.tets[e][static_cast<std::size_t>(k)] = new_node[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])];
    new_tet[static_cast<std::size_t>(old_tet[e])] = static_cast<std::int32_t>(e);
  }
  for (const ElementSet& set : mesh.element_sets) {
    ElementSet& s = out.element_sets.emplace_back(ElementSet{set.tag, set.name, {}});
    s.tets.reserve(set.tets.size());
    for (const std::int32_t e : set.tets) s.tets.push_back(new_tet[static_cast<std::size_t>(e)]);
    std::sort(s.tets.begin(), s.tets.end());
  }
  if (renumbering) *renumbering = {std::move(old_node), std::move(old_tet)};
  return out;
}

std::pair<std::int32_t, std::int32_t> node_range(const TetMesh& mesh, std::size_t first, std::size_t last) {
  if (first >= last) return {0, 0};
  std::int32_t lo = mesh.tets[first][0], hi = lo;
  for (std::size_t e = first; e < last; ++e)
    for (const std::int32_t v : mesh.tets[e]) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  return {lo, hi + 1};
}

}  // namespace viscera::tissue
