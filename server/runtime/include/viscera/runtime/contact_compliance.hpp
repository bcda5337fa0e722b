#pragma once  // SPDX-License-Identifier: Apache-2.0
// The organ's compliance at its surface nodes, for the local force model's stiffness
// (docs/HAPTICS.md section 2): a client renders F(x) = F0 - K (x - x0) between server updates, and K
// must be the contact's stiffness, the tissue in series with the contact penalty, not the penalty
// alone (which would feel like a rigid wall at every update and a soft organ in between).
//
// The tissue's part is its stiffness condensed onto the contact, K = (J K_t^-1 J^T)^-1. The
// tangent stiffness at rest (fixed nodes removed) is factorised once with CHOLMOD; the 3x3 block
// of K_t^-1 at a surface node takes three solves. A worker thread computes the blocks on demand
// and keeps them, so the physics loop never waits: until a node's block is known it gets none,
// and the server falls back to the penalty stiffness (an upper bound).
//
// Approximation, stated: a contact spread over a triangle with barycentric weights w uses
// sum_k w_k C_kk, the node blocks without the coupling between the triangle's nodes; this is the
// compliance of the load applied at one node at a time, an upper bound of the distributed load's.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/model/force_model.hpp"

namespace viscera::runtime {

class ContactCompliance {
 public:
  ContactCompliance(const tissue::ForceModel& model, std::vector<double> density_kg_m3, tissue::BoundaryConditions bc);
  /// A compliance of a model of its own, made by `make_model` on the worker (a cut organ's: its
  /// mesh copied and calibrated again there, so the running organ may go on being cut meanwhile).
  /// `node_count`: the nodes of the model it will make. A model that cannot be made is a failed
  /// factorisation (settled, not ready).
  using ModelMaker = std::function<std::unique_ptr<tissue::ForceModel>()>;
  ContactCompliance(ModelMaker make_model, std::size_t node_count, std::vector<double> density_kg_m3, tissue::BoundaryConditions bc);
  ~ContactCompliance();
  ContactCompliance(const ContactCompliance&) = delete;
  ContactCompliance& operator=(const ContactCompliance&) = delete;

  /// The 3x3 block of K_t^-1 at `node` [m/N] if known; otherwise asks the worker for it and
  /// returns nothing. Never blocks.
  std::optional<Eigen::Matrix3d> node(std::int32_t node);
  /// Blocks until the block of `node` is known (tests, tools and lockstep; not for the live physics
  /// loop); nothing for a node made after the compliance (a cut's), as node() answers.
  std::optional<Eigen::Matrix3d> wait_node(std::int32_t node);
  /// False while the rest stiffness is being factorised or if it could not be.
  bool ready() const { return factorised_.load() == 1; }
  /// True once the worker no longer reads the model (factorised, or failed): from then on the
  /// model may change (a cut). Blocks of nodes made later are never known: the penalty's bound.
  bool settled() const { return factorised_.load() != 0; }
  /// Blocks until settled().
  void wait_settled();

 private:
  explicit ContactCompliance(std::size_t node_count);
  void work(const tissue::ForceModel& model, std::vector<double> density, tissue::BoundaryConditions bc);

  std::unique_ptr<tissue::ForceModel> own_model_;  // the second constructor's (made and read by the worker)
  std::vector<Eigen::Matrix3d> blocks_;
  std::unique_ptr<std::atomic<std::uint8_t>[]> state_;  // per node: 0 unknown, 1 requested, 2 known
  std::atomic<int> factorised_{0};  // 0 pending, 1 done, -1 failed
  std::mutex mutex_;
  std::condition_variable cv_, done_cv_;
  std::deque<std::int32_t> requests_;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace viscera::runtime
