#include "viscera/tissue/cutting/mesh_cutter.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "viscera/tissue/element/tet_geometry.hpp"

namespace viscera::tissue {

namespace {

// The four faces of a tetrahedron, as vertex slots (orientation does not matter here).
constexpr int kTetFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};

bool tet_holds(const Tet& t, std::int32_t n) { return t[0] == n || t[1] == n || t[2] == n || t[3] == n; }

void replace_vertex(Tet& t, std::int32_t from, std::int32_t to) {
  for (auto& v : t)
    if (v == from) v = to;
}

void erase_value(std::vector<std::int32_t>& list, std::int32_t value) {
  const auto it = std::find(list.begin(), list.end(), value);
  if (it != list.end()) list.erase(it);
}

std::uint64_t edge_key(std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// Smallest-index representative with path halving, for the few tetrahedra around one node.
int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i)
    i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
  return i;
}

}  // namespace

std::size_t MeshCutter::FaceHash::operator()(const FaceKey& f) const {
  std::uint64_t h = static_cast<std::uint32_t>(f.a);
  h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(f.b);
  h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(f.c);
  return static_cast<std::size_t>(h ^ (h >> 29));
}

MeshCutter::FaceKey MeshCutter::face_key(std::int32_t a, std::int32_t b, std::int32_t c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {a, b, c};
}

MeshCutter::MeshCutter(TetMesh& mesh, CutOptions options) : mesh_(mesh), options_(options) {
  if (!(options_.snap_fraction > 0.0 && options_.snap_fraction < 0.5))
    throw std::invalid_argument("CutOptions: snap_fraction must lie in (0, 0.5): a crossing at a node would split off a flat tetrahedron");
  node_tets_.resize(mesh_.nodes.size());
  on_cut_.assign(mesh_.nodes.size(), -1);
  cut_point_.assign(mesh_.nodes.size(), Vec3::Zero());
  cut_normal_.assign(mesh_.nodes.size(), Vec3::Zero());
  for (std::size_t e = 0; e < mesh_.tets.size(); ++e)
    for (const std::int32_t v : mesh_.tets[e]) node_tets_[static_cast<std::size_t>(v)].push_back(static_cast<std::int32_t>(e));
  reach_.assign(mesh_.nodes.size(), 0.0);
  for (const Tet& t : mesh_.tets)
    for (const auto& [i, j] : kTetEdges) {
      const double l = 1.5 * (mesh_.nodes[t[j]] - mesh_.nodes[t[i]]).norm();  // edges may stretch by 50%
      reach_[t[i]] = std::max(reach_[t[i]], l);
      reach_[t[j]] = std::max(reach_[t[j]], l);
    }
}

std::int32_t MeshCutter::add_node(const Vec3& rest, const Vec3& now, std::int32_t stroke, const Vec3& cut_point, const Vec3& normal) {
  mesh_.nodes.push_back(rest);
  added_now_.push_back(now);
  node_tets_.emplace_back();
  on_cut_.push_back(stroke);
  reach_.push_back(0.0);
  cut_point_.push_back(cut_point);
  cut_normal_.push_back(normal);
  return static_cast<std::int32_t>(mesh_.nodes.size() - 1);
}

std::vector<std::int32_t> MeshCutter::tets_with(std::span<const std::int32_t> nodes) const {
  std::vector<std::int32_t> out;
  for (const std::int32_t e : node_tets_[static_cast<std::size_t>(nodes[0])]) {
    const Tet& t = mesh_.tets[static_cast<std::size_t>(e)];
    if (std::all_of(nodes.begin() + 1, nodes.end(), [&](std::int32_t n) { return tet_holds(t, n); })) out.push_back(e);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void MeshCutter::remember(std::int32_t e, CutChange& change) {
  if (static_cast<std::size_t>(e) >= change.tets_before || changed_[static_cast<std::size_t>(e)] != 0) return;
  changed_[static_cast<std::size_t>(e)] = 1;
  change.replaced.emplace_back(e, mesh_.tets[static_cast<std::size_t>(e)]);
}

void MeshCutter::split_edge(std::int32_t a, std::int32_t b, double s, std::int32_t stroke, const Vec3& normal, CutChange& change) {
  const std::int32_t ab[2] = {a, b};
  const std::vector<std::int32_t> around = tets_with(ab);
  const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
  const std::int32_t n = add_node((1.0 - s) * mesh_.nodes[ua] + s * mesh_.nodes[ub], (1.0 - s) * now(ua) + s * now(ub), stroke,
                                  (1.0 - s) * now(ua) + s * now(ub), normal);
  change.new_nodes.push_back({a, b, s});
  // The new node's edges lie inside its parents, no longer than their longest edges.
  reach_[static_cast<std::size_t>(n)] = std::max(reach_[ua], reach_[ub]);
  for (const std::int32_t e : around) {
    remember(e, change);
    Tet& parent = mesh_.tets[static_cast<std::size_t>(e)];
    Tet child = parent;
    replace_vertex(child, a, n);  // the part between n and b: (1 - s) of the volume
    replace_vertex(parent, b, n);  // the part between a and n: s of the volume
    const auto c = static_cast<std::int32_t>(mesh_.tets.size());
    for (const std::int32_t v : child)
      if (v != n && v != b) node_tets_[static_cast<std::size_t>(v)].push_back(c);
    mesh_.tets.push_back(child);
    change.origin.push_back(change.origin[static_cast<std::size_t>(e)]);
    for (ElementSet& set : mesh_.element_sets)
      if (std::binary_search(set.tets.begin(), set.tets.end(), e)) set.tets.push_back(c);
    auto& at_b = node_tets_[static_cast<std::size_t>(b)];
    erase_value(at_b, e);
    at_b.push_back(c);
    node_tets_[static_cast<std::size_t>(n)].push_back(e);
    node_tets_[static_cast<std::size_t>(n)].push_back(c);
    // A separated face through the edge is now two separated halves.
    for (const std::int32_t other : child)
      if (other != n && other != b && separated_.erase(face_key(a, b, other)) > 0) {
        separated_.insert(face_key(a, n, other));
        separated_.insert(face_key(n, b, other));
      }
  }
  ++change.split_edges;
}

bool MeshCutter::across_the_cut(const std::int32_t (&face)[3]) const {
  const std::vector<std::int32_t> pair = tets_with(face);
  if (pair.size() != 2) return false;  // on the organ's surface
  Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
  const Vec3& first = cut_normal_[static_cast<std::size_t>(face[0])];
  for (const std::int32_t v : face) {
    point += cut_point_[static_cast<std::size_t>(v)] / 3.0;
    const Vec3& n = cut_normal_[static_cast<std::size_t>(v)];
    normal += n.dot(first) >= 0 ? n : Vec3(-n);  // a blade sawing back and forth flips its normal
  }
  const auto side = [&](std::int32_t e) { return (tet_centroid(mesh_.tets[static_cast<std::size_t>(e)]) - point).dot(normal) >= 0.0; };
  return side(pair[0]) != side(pair[1]);
}

void MeshCutter::separate_faces(std::span<const std::int32_t> touched, std::int32_t stroke, CutChange& change, std::vector<std::int32_t>& opened) {
  std::vector<std::int32_t> tets;
  for (const std::int32_t n : touched) {
    const auto& around = node_tets_[static_cast<std::size_t>(n)];
    tets.insert(tets.end(), around.begin(), around.end());
  }
  std::sort(tets.begin(), tets.end());
  tets.erase(std::unique(tets.begin(), tets.end()), tets.end());
  std::vector<std::int32_t> check;  // tetrahedra on both sides of newly separated faces
  for (const std::int32_t e : tets) {
    const Tet& t = mesh_.tets[static_cast<std::size_t>(e)];
    for (const auto& f : kTetFaces) {
      const std::int32_t face[3] = {t[f[0]], t[f[1]], t[f[2]]};
      if (std::any_of(std::begin(face), std::end(face), [&](std::int32_t v) { return on_cut_[static_cast<std::size_t>(v)] != stroke; })) continue;
      // In the blade's surface, not across it: the two tetrahedra lie on opposite sides of the
      // plane the blade had where these nodes were cut.
      if (!across_the_cut(face)) continue;
      const FaceKey key = face_key(face[0], face[1], face[2]);
      if (separated_.count(key) > 0) continue;
      separated_.insert(key);
      ++change.separated_faces;
      opened.insert(opened.end(), std::begin(face), std::end(face));
      const std::vector<std::int32_t> pair = tets_with(face);
      check.insert(check.end(), pair.begin(), pair.end());
    }
  }
  // A tetrahedron with all four nodes on the cut can find every one of its faces across it (its
  // faces give slightly different planes): one stroke does not cut a single tetrahedron free.
  // It stays joined to the neighbour whose centroid is nearest its own.
  std::sort(check.begin(), check.end());
  check.erase(std::unique(check.begin(), check.end()), check.end());
  for (const std::int32_t e : check) {
    const Tet& t = mesh_.tets[static_cast<std::size_t>(e)];
    const Vec3 centre = tet_centroid(t);
    double nearest = std::numeric_limits<double>::infinity();
    FaceKey keep{};
    bool joined = false;
    for (const auto& f : kTetFaces) {
      const std::int32_t face[3] = {t[f[0]], t[f[1]], t[f[2]]};
      const std::vector<std::int32_t> pair = tets_with(face);
      if (pair.size() != 2) continue;  // the organ's surface
      const FaceKey key = face_key(face[0], face[1], face[2]);
      if (separated_.count(key) == 0) {
        joined = true;
        break;
      }
      const double d = (tet_centroid(mesh_.tets[static_cast<std::size_t>(pair[0] == e ? pair[1] : pair[0])]) - centre).squaredNorm();
      if (d < nearest) {
        nearest = d;
        keep = key;
      }
    }
    if (!joined && std::isfinite(nearest)) {
      separated_.erase(keep);
      ++change.kept_joined;
    }
  }
}

Vec3 MeshCutter::tet_centroid(const Tet& t) const {
  Vec3 c = Vec3::Zero();
  for (const std::int32_t v : t) c += now(static_cast<std::size_t>(v)) / 4.0;
  return c;
}

void MeshCutter::duplicate_if_apart(std::int32_t node, CutChange& change) {
  std::vector<std::int32_t> around = node_tets_[static_cast<std::size_t>(node)];
  std::sort(around.begin(), around.end());
  const int count = static_cast<int>(around.size());
  std::vector<int> parent(static_cast<std::size_t>(count));
  std::iota(parent.begin(), parent.end(), 0);
  // Pairs of tetrahedra joined by a separated face through the node (to re-key after the split).
  struct Joint {
    int i, j;
    std::int32_t p, q;  // the face's other two nodes
  };
  std::vector<Joint> separated_joints;
  for (int i = 0; i < count; ++i) {
    const Tet& ti = mesh_.tets[static_cast<std::size_t>(around[static_cast<std::size_t>(i)])];
    for (int j = i + 1; j < count; ++j) {
      const Tet& tj = mesh_.tets[static_cast<std::size_t>(around[static_cast<std::size_t>(j)])];
      std::int32_t shared[4];
      int k = 0;
      for (const std::int32_t v : ti)
        if (v != node && tet_holds(tj, v)) shared[k++] = v;
      if (k != 2) continue;  // they share no face through the node
      if (separated_.count(face_key(node, shared[0], shared[1])) > 0) {
        separated_joints.push_back({i, j, shared[0], shared[1]});
        continue;
      }
      const int ri = find_root(parent, i), rj = find_root(parent, j);
      if (ri != rj) parent[static_cast<std::size_t>(std::max(ri, rj))] = std::min(ri, rj);
    }
  }
  std::vector<std::int32_t> copy_of_root(static_cast<std::size_t>(count), -1);
  copy_of_root[static_cast<std::size_t>(find_root(parent, 0))] = node;  // the group with the lowest tet keeps the node
  bool apart = false;
  for (int i = 0; i < count; ++i) {
    const int r = find_root(parent, i);
    std::int32_t& id = copy_of_root[static_cast<std::size_t>(r)];
    if (id < 0) {
      const auto u = static_cast<std::size_t>(node);
      id = add_node(mesh_.nodes[u], now(u), on_cut_[u], cut_point_[u], cut_normal_[u]);
      reach_[static_cast<std::size_t>(id)] = reach_[u];
      change.new_nodes.push_back({node, node, 0.0});
      ++change.duplicated_nodes;
      apart = true;
    }
  }
  if (!apart) return;
  for (const Joint& joint : separated_joints) separated_.erase(face_key(node, joint.p, joint.q));
  for (int i = 0; i < count; ++i) {
    const std::int32_t id = copy_of_root[static_cast<std::size_t>(find_root(parent, i))];
    if (id == node) continue;
    const std::int32_t e = around[static_cast<std::size_t>(i)];
    remember(e, change);
    replace_vertex(mesh_.tets[static_cast<std::size_t>(e)], node, id);
    erase_value(node_tets_[static_cast<std::size_t>(node)], e);
    node_tets_[static_cast<std::size_t>(id)].push_back(e);
  }
  // A separated face inside one group is still pending (the cut's front); it now names the
  // group's copy of the node. Faces between groups have opened and are forgotten.
  for (const Joint& joint : separated_joints) {
    const int ri = find_root(parent, joint.i);
    if (ri == find_root(parent, joint.j)) separated_.insert(face_key(copy_of_root[static_cast<std::size_t>(ri)], joint.p, joint.q));
  }
}

void extend_nodal(const CutChange& change, std::vector<Vec3>& values) {
  if (values.size() != change.first_new_node) throw std::invalid_argument("extend_nodal: values do not match the mesh before the change");
  for (const CutChange::NewNode& n : change.new_nodes)
    values.push_back((1.0 - n.t) * values[static_cast<std::size_t>(n.a)] + n.t * values[static_cast<std::size_t>(n.b)]);
}

void extend_flags(const CutChange& change, std::vector<char>& flags) {
  if (flags.size() != change.first_new_node) throw std::invalid_argument("extend_flags: flags do not match the mesh before the change");
  for (const CutChange::NewNode& n : change.new_nodes)
    flags.push_back(static_cast<char>(flags[static_cast<std::size_t>(n.a)] != 0 && flags[static_cast<std::size_t>(n.b)] != 0));
}

CutChange MeshCutter::cut(const BladeSweep& sweep, std::span<const Vec3> x, std::int32_t stroke) {
  if (stroke < 0) throw std::invalid_argument("MeshCutter::cut: stroke ids are >= 0");
  if (x.size() != mesh_.nodes.size()) throw std::invalid_argument("MeshCutter::cut: one position per node expected");
  CutChange change;
  x_ = x;
  added_now_.clear();
  // The patch's mean normal (its two triangles differ by the blade's turn in one tick).
  const Vec3 normal = ((sweep.b0 - sweep.a0) + (sweep.b1 - sweep.a1)).cross((sweep.a1 - sweep.a0) + (sweep.b1 - sweep.b0)).normalized();
  change.first_new_node = mesh_.nodes.size();
  change.tets_before = mesh_.tets.size();
  change.origin.resize(change.tets_before);
  changed_.resize(change.tets_before, 0);
  std::iota(change.origin.begin(), change.origin.end(), 0);

  // 1. Edges near the sweep. An edge that crosses it has both ends within its length of the
  // patch; a node's reach is 1.5 times its longest rest edge (edges may stretch by 50%). Cheap
  // rejections first: ends on one side of the patch (beyond its departure from a
  // plane), or an edge's box that misses the patch's box.
  const Box box = sweep.bounds();
  const Vec3 centre = 0.25 * (sweep.a0 + sweep.b0 + sweep.a1 + sweep.b1);
  double warp = 0.0;
  for (const Vec3* p : {&sweep.a0, &sweep.b0, &sweep.a1, &sweep.b1}) warp = std::max(warp, std::fabs((*p - centre).dot(normal)));
  // Near: within reach of the blade halfway through the sweep, widened by half its travel.
  const Vec3 m0 = 0.5 * (sweep.a0 + sweep.a1), m1 = 0.5 * (sweep.b0 + sweep.b1), blade = m1 - m0;
  const double half_travel = 0.5 * std::max((sweep.a1 - sweep.a0).norm(), (sweep.b1 - sweep.b0).norm());
  const double blade2 = std::max(blade.squaredNorm(), 1e-300);
  // A crossing edge has an end on the patch's front side (or within its warp of the plane), and
  // both its ends are near: the edges are looked for from the near nodes on that side only.
  std::vector<std::int32_t> near;
  for (std::size_t a = 0; a < x.size(); ++a) {
    const double t = std::clamp((x[a] - m0).dot(blade) / blade2, 0.0, 1.0);
    const double r = reach_[a] + half_travel;
    if ((x[a] - m0 - t * blade).squaredNorm() <= r * r && (x[a] - centre).dot(normal) >= -warp) near.push_back(static_cast<std::int32_t>(a));
  }
  near_.resize(x.size(), 0);
  seen_.resize(x.size(), 0);
  for (const std::int32_t a : near) near_[static_cast<std::size_t>(a)] = 1;
  struct Crossing {
    std::uint64_t key;
    double s;
    bool operator<(const Crossing& o) const { return key < o.key; }
  };
  std::vector<Crossing> found;
  for (const std::int32_t a : near) {
    const Vec3& xa = x[static_cast<std::size_t>(a)];
    const double da = (xa - centre).dot(normal);
    if (++seen_tag_ == 0) {  // the tags wrapped: forget them all
      std::fill(seen_.begin(), seen_.end(), 0u);
      seen_tag_ = 1;
    }
    for (const std::int32_t e : node_tets_[static_cast<std::size_t>(a)])
      for (const std::int32_t b : mesh_.tets[static_cast<std::size_t>(e)]) {
        std::uint32_t& seen = seen_[static_cast<std::size_t>(b)];
        if (seen == seen_tag_) continue;  // a neighbour in several of a's tetrahedra: once
        seen = seen_tag_;
        if (b == a || (near_[static_cast<std::size_t>(b)] != 0 && b < a)) continue;  // b's turn
        if (on_cut_[static_cast<std::size_t>(a)] == stroke && on_cut_[static_cast<std::size_t>(b)] == stroke) continue;
        const Vec3& xb = x[static_cast<std::size_t>(b)];
        const double db = (xb - centre).dot(normal);
        if ((da > warp && db > warp) || (da < -warp && db < -warp)) continue;
        if ((xa.cwiseMin(xb).array() > box.hi.array()).any() || (xa.cwiseMax(xb).array() < box.lo.array()).any()) continue;
        const auto lo = std::min(a, b), hi = std::max(a, b);
        if (const auto s = sweep_crossing(sweep, x[static_cast<std::size_t>(lo)], x[static_cast<std::size_t>(hi)]))
          found.push_back({edge_key(lo, hi), *s});
      }
  }
  for (const std::int32_t a : near) near_[static_cast<std::size_t>(a)] = 0;
  std::sort(found.begin(), found.end());  // in the order of the edges' keys, whatever the scan's

  struct Split {
    std::int32_t a, b;
    double s;
  };
  std::vector<Split> crossings;
  std::vector<std::int32_t> touched;
  const auto snap = [&](std::int32_t n, const Vec3& crossing) {
    if (on_cut_[static_cast<std::size_t>(n)] == stroke) return;
    on_cut_[static_cast<std::size_t>(n)] = stroke;
    cut_point_[static_cast<std::size_t>(n)] = crossing;
    cut_normal_[static_cast<std::size_t>(n)] = normal;
    touched.push_back(n);
    ++change.snapped_nodes;
  };
  const double d = options_.snap_fraction;
  for (const Crossing& c : found) {
    const auto a = static_cast<std::int32_t>(c.key >> 32), b = static_cast<std::int32_t>(c.key & 0xffffffffu);
    const Vec3 crossing = (1.0 - c.s) * x[static_cast<std::size_t>(a)] + c.s * x[static_cast<std::size_t>(b)];
    if (c.s < d)
      snap(a, crossing);
    else if (c.s > 1.0 - d)
      snap(b, crossing);
    else
      crossings.push_back({a, b, c.s});
  }
  // 2. Split what is left. An edge with an end on this stroke's cut is not split: the surface
  // already passes through that end.
  for (const Split& c : crossings) {
    if (on_cut_[static_cast<std::size_t>(c.a)] == stroke || on_cut_[static_cast<std::size_t>(c.b)] == stroke) continue;
    split_edge(c.a, c.b, c.s, stroke, normal, change);
    touched.push_back(static_cast<std::int32_t>(mesh_.nodes.size() - 1));
  }
  // 3. Faces of the cut surface, and the nodes where the mesh came apart.
  std::vector<std::int32_t> opened;
  separate_faces(touched, stroke, change, opened);
  std::sort(opened.begin(), opened.end());
  opened.erase(std::unique(opened.begin(), opened.end()), opened.end());
  for (const std::int32_t n : opened) duplicate_if_apart(n, change);
  x_ = {};
  added_now_.clear();
  for (const auto& [e, tet] : change.replaced) changed_[static_cast<std::size_t>(e)] = 0;
  return change;
}

}  // namespace viscera::tissue
