#pragma once  // SPDX-License-Identifier: Apache-2.0
// A symmetric positive definite sparse matrix with a fixed pattern (upper triangle, compressed
// columns) and its CHOLMOD Cholesky factorisation. The symbolic analysis (fill-reducing ordering)
// is done once; each factorize() redoes only the numeric part.
#include <span>
#include <vector>

namespace viscera::tissue {

class SparseCholesky {
 public:
  /// Pattern of the upper triangle: column pointers (n+1) and sorted row indices per column.
  SparseCholesky(int n, std::vector<int> column_pointers, std::vector<int> row_indices);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  int size() const { return n_; }
  /// Values in pattern order; fill them, then factorize().
  std::span<double> values();
  /// Position of entry (row, col), row <= col, in values(); -1 if not in the pattern.
  long slot(int row, int col) const;
  /// Numeric factorisation; false if the matrix is not positive definite.
  bool factorize();
  /// Solves A x = b with the last factorisation.
  void solve(std::span<const double> b, std::span<double> x);

 private:
  struct Impl;
  Impl* impl_;
  int n_;
  std::vector<int> column_pointers_, row_indices_;
};

}  // namespace viscera::tissue
