#pragma once  // SPDX-License-Identifier: Apache-2.0
// The one interface the integrators use: internal elastic forces, the potential energy, and
// per-element tangent stiffness blocks. A model is immutable after construction, so the same
// positions give the same forces bit for bit (no hidden state).
#include <memory>
#include <span>
#include <string_view>
#include <utility>

#include "viscera/tissue/element/tet_geometry.hpp"
#include "viscera/tissue/mesh/tet_mesh.hpp"

namespace viscera::tissue {

/// Memory variables (viscoelasticity) of a model live in State::memory, not in the model, so that
/// models stay immutable and a state can be copied, rolled back or replayed. An evaluation
/// advances them from `before` (at the previous evaluation) by dt_s to the positions x into
/// `after` (which may be the same storage: each element reads its values before writing them).
struct MemoryUpdate {
  std::span<const double> before;
  std::span<double> after;
  double dt_s = 0.0;
};

/// By-product of one force evaluation: the largest absolute edge strain |L - L0| / L0 seen
/// (NaN if any was NaN). The explicit integrator uses it to detect instability cheaply.
struct ForceStats {
  double max_edge_strain = 0.0;
};

/// A mesh edited in place (cutting, docs/CUTTING.md): nodes and elements appended, some elements
/// given new vertices; no node moves. What a model and an integrator need to follow it.
struct MeshEdit {
  /// A new node at (1 - t) x[a] + t x[b] (t = 0 and a = b for a copy of a), possibly of a node
  /// made before it in the same edit.
  struct NewNode {
    std::int32_t a = 0, b = 0;
    double t = 0.0;
  };
  std::size_t nodes_before = 0, elements_before = 0;
  std::span<const NewNode> new_nodes;  ///< nodes nodes_before, nodes_before + 1, ...
  /// Per element after the edit, the element before it that it comes from (itself if unchanged).
  std::span<const std::int32_t> origin;
  /// Every element before the edit whose vertices changed, with its vertices before.
  std::span<const std::pair<std::int32_t, Tet>> replaced;
};

/// Part `index` of `count` of a model's elements, for evaluating forces on several threads: the
/// parts together are all elements, and each part advances only its own elements' memory.
struct ElementPart {
  std::size_t index = 0, count = 1;
};

class ForceModel {
 public:
  explicit ForceModel(std::shared_ptr<const TetMesh> rest_mesh);
  virtual ~ForceModel() = default;
  ForceModel(const ForceModel&) = delete;
  ForceModel& operator=(const ForceModel&) = delete;

  /// Short name used in benchmarks and reports ("gps", "gps_energy", "corotational", "linear").
  virtual std::string_view name() const = 0;

  /// f += internal forces [N] at positions x [m].
  virtual ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f) const = 0;

  /// Models with memory variables: the number of doubles they keep in State::memory (0: none).
  virtual std::size_t memory_size() const { return 0; }
  /// f += forces at x with the memory advanced as described by `memory`. Models without memory
  /// ignore it.
  virtual ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory) const {
    (void)memory;
    return add_forces(x, f);
  }
  /// f += the forces of one part of the elements, memory advanced for that part only. Summed over
  /// all parts, the forces of add_forces(x, f, memory) up to rounding. Models that do not split
  /// compute everything in part 0 and nothing in the others.
  virtual ForceStats add_forces(std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& memory, ElementPart part) const {
    return part.index == 0 ? add_forces(x, f, memory) : ForceStats{};
  }
  /// The elements [first, last) whose forces that part computes (it writes only to their nodes).
  virtual std::pair<std::size_t, std::size_t> part_elements(ElementPart part) const {
    return part.index == 0 ? std::pair<std::size_t, std::size_t>{0, element_count()} : std::pair<std::size_t, std::size_t>{0, 0};
  }
  /// Tangent of the forces of a step of dt_s (memory variables make the stiffness depend on dt).
  virtual Mat12 element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s) const {
    (void)dt_s;
    return element_tangent(x, e);
  }
  /// The same with the memory at the start of the step, for models whose elasticity depends on
  /// their history (first-load softening); the others ignore it.
  virtual Mat12 element_tangent(std::span<const Vec3> x, std::size_t e, double dt_s, std::span<const double> memory) const {
    (void)memory;
    return element_tangent(x, e, dt_s);
  }
  /// Stiffness-proportional (Kelvin-Voigt) damping time [s], which shortens the explicit step.
  virtual double stiffness_damping_time_s() const { return 0.0; }
  /// How many times stiffer than at rest an element's tangent may be while no edge strain
  /// |dL| / L0 exceeds `edge_strain` (>= 1; 1 for a model without strain stiffening). The
  /// explicit integrator shortens its step by its square root.
  virtual double stiffness_growth(double edge_strain) const {
    (void)edge_strain;
    return 1.0;
  }

  /// Elastic potential energy [J]. For the paper-form GPS (not conservative at finite strain)
  /// this is the energy of its energy-consistent sibling, 0.5 dL^T H dL.
  virtual double energy(std::span<const Vec3> x) const = 0;

  /// Tangent stiffness K = -df/dx of element e (12x12, in the tet's vertex order) at x.
  /// Non-conservative models return their non-symmetric tangent; integrators symmetrise.
  virtual Mat12 element_tangent(std::span<const Vec3> x, std::size_t e) const = 0;

  const TetMesh& rest_mesh() const { return *mesh_; }
  std::size_t node_count() const { return mesh_->nodes.size(); }
  std::size_t element_count() const { return mesh_->tets.size(); }
  const Tet& element(std::size_t e) const { return mesh_->tets[e]; }

  /// Positions of element e's four vertices in x.
  std::array<Vec3, 4> gather(std::span<const Vec3> x, std::size_t e) const {
    const Tet& t = mesh_->tets[e];
    return {x[t[0]], x[t[1]], x[t[2]], x[t[3]]};
  }

  /// Largest |L - L0| / L0 over the six edges of element e at x (NaN if non-finite).
  double element_max_edge_strain(std::span<const Vec3> x, std::size_t e) const;

 protected:
  std::shared_ptr<const TetMesh> mesh_;
};

/// The element with the largest edge strain at x (a NaN strain counts as the largest).
std::size_t find_max_strain_element(const ForceModel& model, std::span<const Vec3> x);

}  // namespace viscera::tissue
