#include "viscera/tissue/integrator/sparse_cholesky.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <cholmod.h>

namespace viscera::tissue {

struct SparseCholesky::Impl {
  cholmod_common common{};
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  cholmod_dense* b = nullptr;
};

SparseCholesky::SparseCholesky(int n, std::vector<int> column_pointers, std::vector<int> row_indices)
    : impl_(new Impl), n_(n), column_pointers_(std::move(column_pointers)), row_indices_(std::move(row_indices)) {
  if (static_cast<int>(column_pointers_.size()) != n + 1) throw std::invalid_argument("SparseCholesky: column pointer count");
  cholmod_start(&impl_->common);
  impl_->common.print = 0;
  impl_->common.error_handler = nullptr;
  const auto nnz = static_cast<size_t>(column_pointers_.back());
  impl_->A = cholmod_allocate_sparse(static_cast<size_t>(n), static_cast<size_t>(n), nnz, 1, 1, 1, CHOLMOD_REAL, &impl_->common);
  if (!impl_->A) throw std::runtime_error("CHOLMOD: cannot allocate the matrix");
  std::memcpy(impl_->A->p, column_pointers_.data(), sizeof(int) * column_pointers_.size());
  std::memcpy(impl_->A->i, row_indices_.data(), sizeof(int) * nnz);
  std::fill_n(static_cast<double*>(impl_->A->x), nnz, 0.0);
  impl_->b = cholmod_zeros(static_cast<size_t>(n), 1, CHOLMOD_REAL, &impl_->common);
}

SparseCholesky::~SparseCholesky() {
  if (impl_->L) cholmod_free_factor(&impl_->L, &impl_->common);
  if (impl_->A) cholmod_free_sparse(&impl_->A, &impl_->common);
  if (impl_->b) cholmod_free_dense(&impl_->b, &impl_->common);
  cholmod_finish(&impl_->common);
  delete impl_;
}

std::span<double> SparseCholesky::values() { return {static_cast<double*>(impl_->A->x), static_cast<size_t>(column_pointers_.back())}; }

long SparseCholesky::slot(int row, int col) const {
  const auto begin = row_indices_.begin() + column_pointers_[col];
  const auto end = row_indices_.begin() + column_pointers_[col + 1];
  const auto it = std::lower_bound(begin, end, row);
  return (it != end && *it == row) ? static_cast<long>(it - row_indices_.begin()) : -1;
}

bool SparseCholesky::factorize() {
  if (!impl_->L) {
    impl_->L = cholmod_analyze(impl_->A, &impl_->common);
    if (!impl_->L) throw std::runtime_error("CHOLMOD: symbolic analysis failed");
  }
  const int ok = cholmod_factorize(impl_->A, impl_->L, &impl_->common);
  return ok && impl_->common.status == CHOLMOD_OK;
}

void SparseCholesky::solve(std::span<const double> b, std::span<double> x) {
  std::memcpy(impl_->b->x, b.data(), sizeof(double) * static_cast<size_t>(n_));
  cholmod_dense* sol = cholmod_solve(CHOLMOD_A, impl_->L, impl_->b, &impl_->common);
  if (!sol) throw std::runtime_error("CHOLMOD: solve failed");
  std::memcpy(x.data(), sol->x, sizeof(double) * static_cast<size_t>(n_));
  cholmod_free_dense(&sol, &impl_->common);
}

}  // namespace viscera::tissue
