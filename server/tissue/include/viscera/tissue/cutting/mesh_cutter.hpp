#pragma once  // SPDX-License-Identifier: Apache-2.0
// Cutting a tetrahedral mesh with the surface a blade sweeps (docs/CUTTING.md).
//
// The method, in three steps per sweep:
//  1. Every mesh edge the swept surface crosses is found (in the current positions). A crossing
//     within `snap_fraction` of an edge's length from one end snaps to that node: the node is
//     put on the cut and the edge is left whole. Any other crossing is kept.
//  2. Each kept edge is split at its crossing (edge bisection at the parameter s: a new node on
//     the edge, each tetrahedron around the edge replaced by the two on either side of it, so the
//     mesh stays conforming). The new node is on the cut. Every child has at least
//     min(s, 1 - s) >= snap_fraction of its parent's volume, so snapping is what keeps slivers out.
//  3. A face whose three nodes are all on the cut of the same stroke, and whose two
//     tetrahedra lie on opposite sides of the blade's plane where those nodes were cut, is a face
//     of the cut
//     surface: it is marked separated. A node on a separated face is duplicated when its
//     tetrahedra fall into more than one group connected through unseparated faces: each further
//     group gets its own copy. At the cut's front the groups still connect around the node, so
//     the cut opens only where the blade has passed completely; the front waits, it never tears.
// Nothing is deleted: volume and mass stay, new nodes are interpolated along their edge.
#include <cstdint>
#include <span>
#include <unordered_set>
#include <utility>
#include <vector>

#include "viscera/tissue/cutting/blade_sweep.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::tissue {

struct CutOptions {
  /// Crossings closer than this fraction of an edge's length to one of its ends snap to it, in
  /// (0, 0.5). 0.2 measured best (docs/CUTTING.md): smaller leaves slivers, larger a jagged cut.
  double snap_fraction = 0.2;
};

/// What one sweep changed, for the caller to bring positions, velocities, fixed nodes, masses and
/// the force model along. The mesh's rest positions and tetrahedra are already changed.
struct CutChange {
  /// Node `first_new_node + i`, in the order made (a node may be made from one before it).
  using NewNode = MeshEdit::NewNode;
  std::size_t first_new_node = 0;
  std::vector<NewNode> new_nodes;
  /// For every tetrahedron of the mesh after the change, the one of the mesh before it comes from
  /// (itself when unchanged); size: the tet count after.
  std::vector<std::int32_t> origin;
  std::size_t tets_before = 0;
  /// Every tetrahedron of the mesh before whose vertices changed, with its vertices before.
  std::vector<std::pair<std::int32_t, Tet>> replaced;
  std::size_t split_edges = 0;  ///< edges bisected
  std::size_t snapped_nodes = 0;  ///< nodes put on the cut instead of splitting an edge
  std::size_t separated_faces = 0;  ///< faces of the cut surface completed by this sweep
  std::size_t duplicated_nodes = 0;  ///< copies made where the mesh came apart
  std::size_t kept_joined = 0;  ///< tetrahedra that every face would have cut free, kept joined by one

  bool topology_changed() const { return !new_nodes.empty() || origin.size() != tets_before || separated_faces > 0; }
  /// The change as the force model and the integrator follow it (views into this change).
  MeshEdit edit() const { return {first_new_node, tets_before, new_nodes, origin, replaced}; }
};

/// Per-node values at a change's new nodes, interpolated along their edge (positions,
/// velocities) or copied.
void extend_nodal(const CutChange& change, std::vector<Vec3>& values);
/// Per-node flags (fixed nodes) at a change's new nodes: a node on an edge is flagged when both
/// ends are, a copy when its source is.
void extend_flags(const CutChange& change, std::vector<char>& flags);

class MeshCutter {
 public:
  /// Cuts `mesh` in place (it must outlive the cutter, and only the cutter may change it).
  explicit MeshCutter(TetMesh& mesh, CutOptions options = {});

  /// Cuts with the surface `sweep` (current positions x, one per node of the mesh, [m]) as part
  /// of stroke `stroke` (one stroke: one continuous pass of the blade, ids >= 0). Edges already
  /// cut by this stroke and faces already separated are not cut again.
  CutChange cut(const BladeSweep& sweep, std::span<const Vec3> x, std::int32_t stroke);

  const TetMesh& mesh() const { return mesh_; }
  /// The stroke whose cut a node lies on (-1: none).
  std::int32_t node_stroke(std::int32_t node) const { return on_cut_[static_cast<std::size_t>(node)]; }
  /// Faces of the cut surface that still join two tetrahedra (the cut's front, not yet open).
  std::size_t pending_faces() const { return separated_.size(); }
  /// Tetrahedra around each node.
  const std::vector<std::vector<std::int32_t>>& node_tets() const { return node_tets_; }

 private:
  struct FaceKey {
    std::int32_t a, b, c;  // ascending
    bool operator==(const FaceKey&) const = default;
  };
  struct FaceHash {
    std::size_t operator()(const FaceKey& f) const;
  };
  static FaceKey face_key(std::int32_t a, std::int32_t b, std::int32_t c);

  std::int32_t add_node(const Vec3& rest, const Vec3& now, std::int32_t stroke, const Vec3& cut_point, const Vec3& normal);
  /// Whether the two tetrahedra on an interior face lie on opposite sides of the blade's plane
  /// where the face's nodes were cut (false on the organ's surface).
  bool across_the_cut(const std::int32_t (&face)[3]) const;
  Vec3 tet_centroid(const Tet& t) const;  ///< in the current positions
  /// Records tetrahedron e's vertices before this change, the first time it changes.
  void remember(std::int32_t e, CutChange& change);
  void split_edge(std::int32_t a, std::int32_t b, double s, std::int32_t stroke, const Vec3& normal, CutChange& change);
  /// Tetrahedra holding all of the given nodes.
  std::vector<std::int32_t> tets_with(std::span<const std::int32_t> nodes) const;
  void separate_faces(std::span<const std::int32_t> touched, std::int32_t stroke, CutChange& change, std::vector<std::int32_t>& opened);
  void duplicate_if_apart(std::int32_t node, CutChange& change);

  TetMesh& mesh_;
  CutOptions options_;
  std::vector<std::vector<std::int32_t>> node_tets_;
  std::vector<std::int32_t> on_cut_;
  std::vector<Vec3> cut_point_;  ///< where the blade's surface crossed the mesh at a node (current, when cut)
  std::vector<Vec3> cut_normal_;  ///< unit normal of the blade's surface there
  /// During cut(): the current positions given, and those of the nodes made since.
  std::span<const Vec3> x_;
  std::vector<Vec3> added_now_;
  const Vec3& now(std::size_t n) const { return n < x_.size() ? x_[n] : added_now_[n - x_.size()]; }
  std::vector<char> changed_;  ///< during cut(): tetrahedra already in CutChange::replaced
  std::vector<char> near_;  ///< during cut(): nodes near the sweep (all 0 between calls)
  std::vector<std::uint32_t> seen_;  ///< during cut(): the tag of the last node whose neighbours reached it
  std::uint32_t seen_tag_ = 0;
  std::unordered_set<FaceKey, FaceHash> separated_;
  std::vector<double> reach_;  ///< per node, 1.5 x its longest rest edge [m] (splits only shorten edges)
};

}  // namespace viscera::tissue
