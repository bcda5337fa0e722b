// GpsModel after cutting: the memory of tetrahedra cut from others (memory_from), and following an  // SPDX-License-Identifier: Apache-2.0
// edit of the mesh in place (follow_edit).
#include <algorithm>
#include <stdexcept>

#include <Eigen/LU>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/model/reserve_resident.hpp"

namespace viscera::tissue {

namespace {

constexpr std::size_t kLane = GpsModel::kLanes;  // (L is gps_model.cpp's, in the same unity build)

// dL = A eps (Voigt, engineering shear): row k is L0_k times n_k's quadratic form.
Mat6 elongation_of_strain(const std::array<Vec3, 4>& rest) {
  Mat6 A;
  for (int k = 0; k < 6; ++k) {
    const Vec3 y = rest[kTetEdges[k][1]] - rest[kTetEdges[k][0]];
    const double l = y.norm();
    const Vec3 n = y / l;
    A.row(k) << n.x() * n.x(), n.y() * n.y(), n.z() * n.z(), n.y() * n.z(), n.x() * n.z(), n.x() * n.y();
    A.row(k) *= l;
  }
  return A;
}

}  // namespace

void GpsModel::carry_memory(const double* in, const std::array<Vec3, 4>& parent_rest, const Mat6& parent_h, double* to, std::size_t e) const {
  const auto child_rest = gather(mesh_->nodes, e);
  const bool same = child_rest == parent_rest;
  Mat6 map = Mat6::Identity();
  // The large-strain GPS's memory is its backbone's stress in the rest frame: a piece of a cut
  // element holds its parent's.
  if (!same && neo_.empty()) {
    map = elongation_of_strain(child_rest) * elongation_of_strain(parent_rest).fullPivLu().inverse();
    // The energy form of Fung's map keeps tensions, t = H dL at small strain.
    if (options_.mechanisms.energy_map()) map = packed_hessian(e) * map * parent_h.fullPivLu().inverse();
  }
  for (std::size_t v = 0; v < 1 + mechanisms_; ++v) {  // previous elongation (or tension), then zeta_l
    Vec6 q;
    for (int k = 0; k < 6; ++k) q(k) = in[(v * 6 + static_cast<std::size_t>(k)) * kLane];
    const Vec6 r = map * q;
    for (int k = 0; k < 6; ++k) to[(v * 6 + static_cast<std::size_t>(k)) * kLane] = r(k);
  }
  if (options_.mechanisms.softening.active())
    for (std::size_t sense = 0; sense < 2; ++sense) {
      const std::size_t at = softening_offset() + sense * 6 * kLane;
      double peak = 0.0;
      for (std::size_t k = 0; k < 6; ++k) peak = std::max(peak, in[at + k * kLane]);
      for (std::size_t k = 0; k < 6; ++k) to[at + k * kLane] = same ? in[at + k * kLane] : peak;
    }
}

std::vector<double> GpsModel::memory_from(const GpsModel& before, std::span<const double> memory, std::span<const std::int32_t> origin) const {
  std::vector<double> out(memory_size(), 0.0);  // padding lanes: zero, their H is zero
  if (out.empty()) return out;
  if (before.memory_size() != memory.size() || before.mechanisms_ != mechanisms_ || before.memory_stride() != memory_stride())
    throw std::invalid_argument("GpsModel::memory_from: the models' memory layouts differ");
  if (origin.size() != element_count()) throw std::invalid_argument("GpsModel::memory_from: one origin per element expected");
  const std::size_t stride = memory_stride();
  for (std::size_t e = 0; e < element_count(); ++e) {
    const auto p = static_cast<std::size_t>(origin[e]);
    if (p >= before.element_count()) throw std::invalid_argument("GpsModel::memory_from: origin names no element of the model before");
    carry_memory(memory.data() + (p / kLane) * stride + p % kLane, before.gather(before.mesh_->nodes, p), before.packed_hessian(p),
                 out.data() + (e / kLane) * stride + e % kLane, e);
  }
  return out;
}

void GpsModel::reserve_elements(std::size_t elements) {
  reserve_resident(blocks_, (elements + kLane - 1) / kLane);
  if (!bulk_.empty()) reserve_resident(bulk_, (elements + kLane - 1) / kLane);
  if (!neo_.empty()) reserve_resident(neo_, (elements + kLane - 1) / kLane);
}

std::size_t GpsModel::memory_size_for(std::size_t elements) const {
  return options_.mechanisms.has_memory() ? (elements + kLane - 1) / kLane * memory_stride() : 0;
}

void GpsModel::follow_edit(const MeshEdit& edit, std::vector<double>& memory) {
  const std::size_t n = element_count(), before = edit.elements_before;
  if (edit.origin.size() != n || before > n || blocks_.size() != (before + kLane - 1) / kLane)
    throw std::invalid_argument("GpsModel::follow_edit: the edit does not match the model and its mesh");
  // Empty memory is a relaxed organ (State::at_rest): nothing to carry, and it stays empty.
  const bool with_memory = options_.mechanisms.has_memory() && !memory.empty();
  if (with_memory && memory.size() != memory_size()) throw std::invalid_argument("GpsModel::follow_edit: memory of another layout");
  const std::size_t stride = memory_stride();
  // The parents' rest shapes, H and memory before anything is rewritten (nodes never move, so
  // the vertices before give the rest shape before). A parent's memory goes to lane 0 of a
  // block-sized slot of its own, in the layout carry_memory reads.
  const std::size_t parents = edit.replaced.size();
  std::vector<std::array<Vec3, 4>> parent_rest(parents);
  std::vector<Mat6> parent_h(with_memory ? parents : 0);
  std::vector<double> parent_memory(with_memory ? parents * stride : 0);
  // The parents by element, each with its slot: looked up by a child's origin without a pass over
  // the whole model (a sweep of the 12k liver replaces a few tens of its elements).
  std::vector<std::pair<std::int32_t, std::int32_t>> slot_of(parents);
  const auto& X = mesh_->nodes;
  for (std::size_t i = 0; i < parents; ++i) {
    const auto& [element, tet] = edit.replaced[i];
    const auto e = static_cast<std::size_t>(element);
    if (element < 0 || e >= before) throw std::invalid_argument("GpsModel::follow_edit: a replaced element is out of range or repeated");
    slot_of[i] = {element, static_cast<std::int32_t>(i)};
    parent_rest[i] = {X[tet[0]], X[tet[1]], X[tet[2]], X[tet[3]]};
    if (!with_memory) continue;
    parent_h[i] = packed_hessian(e);  // as write_lane calibrated it (its lane is rewritten below)
    for (std::size_t w = 0; w < stride / kLane; ++w) parent_memory[i * stride + w * kLane] = memory[(e / kLane) * stride + w * kLane + e % kLane];
  }
  std::sort(slot_of.begin(), slot_of.end());
  for (std::size_t i = 1; i < parents; ++i)
    if (slot_of[i].first == slot_of[i - 1].first)
      throw std::invalid_argument("GpsModel::follow_edit: a replaced element is out of range or repeated");
  const auto parent_slot = [&](std::size_t p) {  // the parent's slot, -1 if p was not replaced
    const auto it = std::lower_bound(slot_of.begin(), slot_of.end(), std::pair<std::int32_t, std::int32_t>{static_cast<std::int32_t>(p), -1});
    return it != slot_of.end() && it->first == static_cast<std::int32_t>(p) ? it->second : -1;
  };
  // The changed elements in ascending order: the replaced, then the new ones.
  std::vector<std::int32_t> changed;
  changed.reserve(parents + (n - before));
  for (const auto& parent : slot_of) changed.push_back(parent.first);
  for (std::size_t e = before; e < n; ++e) changed.push_back(static_cast<std::int32_t>(e));
  for (const std::int32_t e : changed) {
    const auto p = static_cast<std::size_t>(edit.origin[static_cast<std::size_t>(e)]);
    if (p >= before) throw std::invalid_argument("GpsModel::follow_edit: an origin names no element before the edit");
    if (parent_slot(p) < 0) throw std::invalid_argument("GpsModel::follow_edit: a new element's parent is not among the replaced");
  }
  if (!material_of_tet_.empty())
    for (std::size_t e = before; e < n; ++e) material_of_tet_.push_back(material_of_tet_[static_cast<std::size_t>(edit.origin[e])]);
  // Grow the blocks, rewrite the changed lanes and the last block's padding.
  blocks_.resize((n + kLane - 1) / kLane);
  if (!bulk_.empty()) bulk_.resize(blocks_.size());
  if (!neo_.empty()) neo_.resize(blocks_.size());
  for (const std::int32_t e : changed) write_lane(static_cast<std::size_t>(e));
  for (std::size_t slot = n; slot < blocks_.size() * kLane; ++slot) write_lane(slot);
  if (!with_memory) return;
  memory.resize(memory_size(), 0.0);
  for (const std::int32_t element : changed) {
    const auto e = static_cast<std::size_t>(element);
    const auto i = static_cast<std::size_t>(parent_slot(static_cast<std::size_t>(edit.origin[e])));
    carry_memory(parent_memory.data() + i * stride, parent_rest[i], parent_h[i], memory.data() + (e / kLane) * stride + e % kLane, e);
  }
  // Padding lanes: zero memory, as a new model's.
  for (std::size_t slot = n; slot < blocks_.size() * kLane; ++slot)
    for (std::size_t w = 0; w < stride / kLane; ++w) memory[(slot / kLane) * stride + w * kLane + slot % kLane] = 0.0;
}

}  // namespace viscera::tissue
