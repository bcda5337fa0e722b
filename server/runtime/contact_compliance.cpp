#include "viscera/runtime/contact_compliance.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <pthread.h>

#include "viscera/tissue/integrator/implicit_integrator.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;

ContactCompliance::ContactCompliance(std::size_t node_count)
    : blocks_(node_count, Eigen::Matrix3d::Zero()), state_(std::make_unique<std::atomic<std::uint8_t>[]>(node_count)) {
  for (std::size_t i = 0; i < blocks_.size(); ++i) state_[i] = 0;
}

ContactCompliance::ContactCompliance(const ForceModel& model, std::vector<double> density_kg_m3, BoundaryConditions bc)
    : ContactCompliance(model.rest_mesh().node_count()) {
  worker_ = std::thread(
      [this, &model, density = std::move(density_kg_m3), bc = std::move(bc)]() mutable { work(model, std::move(density), std::move(bc)); });
}

ContactCompliance::ContactCompliance(ModelMaker make_model, std::size_t node_count, std::vector<double> density_kg_m3, BoundaryConditions bc)
    : ContactCompliance(node_count) {
  worker_ = std::thread([this, make = std::move(make_model), density = std::move(density_kg_m3), bc = std::move(bc)]() mutable {
    try {
      own_model_ = make();
    } catch (const std::exception&) {
      own_model_.reset();
    }
    if (!own_model_ || own_model_->node_count() != blocks_.size()) {
      {
        std::lock_guard lock(mutex_);
        factorised_ = -1;
      }
      done_cv_.notify_all();
      return;
    }
    work(*own_model_, std::move(density), std::move(bc));
  });
}

ContactCompliance::~ContactCompliance() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
}

std::optional<Eigen::Matrix3d> ContactCompliance::node(std::int32_t n) {
  const auto i = static_cast<std::size_t>(n);
  if (i >= blocks_.size()) return std::nullopt;  // a node a cut made: not in the factorised organ
  if (state_[i].load(std::memory_order_acquire) == 2) return blocks_[i];
  std::uint8_t unknown = 0;
  if (factorised_.load() >= 0 && state_[i].compare_exchange_strong(unknown, 1)) {
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) {
      state_[i] = 0;  // ask again next time rather than wait for the worker's lock
      return std::nullopt;
    }
    requests_.push_back(n);
    lock.unlock();
    cv_.notify_one();
  }
  return std::nullopt;
}

void ContactCompliance::wait_settled() {
  std::unique_lock lock(mutex_);
  done_cv_.wait(lock, [this] { return factorised_.load() != 0; });
}

std::optional<Eigen::Matrix3d> ContactCompliance::wait_node(std::int32_t n) {
  if (static_cast<std::size_t>(n) >= blocks_.size()) return std::nullopt;  // as node() answers it
  for (;;) {
    if (auto b = node(n)) return *b;
    if (factorised_.load() < 0) throw std::runtime_error("the organ's rest stiffness could not be factorised");
    std::unique_lock lock(mutex_);
    done_cv_.wait_for(lock, std::chrono::milliseconds(10));
  }
}

namespace {
// CHOLMOD's dense kernels run on Debian's serial OpenBLAS, which must not be called from two
// threads at once (two organs' workers factorising together, during a material change or a scene
// load, crashed in dpotrf under ThreadSanitizer's timing): every factorisation and solve of every
// compliance in the process takes this lock.
std::mutex g_blas_mutex;
}  // namespace

void ContactCompliance::work(const ForceModel& model, std::vector<double> density, BoundaryConditions bc) {
  pthread_setname_np(pthread_self(), "compliance");
  bc.force_field = nullptr;  // instruments are not part of the organ's own stiffness
  bc.gravity_m_s2 = Vec3::Zero();
  {
    std::lock_guard lock(mutex_);
    if (stop_) return;  // destroyed before it began: nothing waits for it
  }
  const auto& rest = model.rest_mesh().nodes;
  // dt is irrelevant to the static stiffness; the integrator only needs a valid one.
  ImplicitIntegrator system(model, std::move(density), std::move(bc), ImplicitOptions{1e-3});
  {
    std::lock_guard blas(g_blas_mutex);
    const int outcome = system.factorize_stiffness(rest) ? 1 : -1;
    std::lock_guard lock(mutex_);  // wait_settled() must not miss the notification
    factorised_ = outcome;
  }
  done_cv_.notify_all();
  if (factorised_ < 0) return;
  std::vector<Vec3> f(rest.size(), Vec3::Zero()), u(rest.size());
  for (;;) {
    std::int32_t n;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, [this] { return stop_ || !requests_.empty(); });
      if (stop_) return;
      n = requests_.front();
      requests_.pop_front();
    }
    const auto i = static_cast<std::size_t>(n);
    std::lock_guard blas(g_blas_mutex);
    for (int d = 0; d < 3; ++d) {
      f[i] = Vec3::Unit(d);
      system.compliance(f, u);
      blocks_[i].col(d) = u[i];
    }
    f[i] = Vec3::Zero();
    state_[i].store(2, std::memory_order_release);
    done_cv_.notify_all();
  }
}

}  // namespace viscera::runtime
