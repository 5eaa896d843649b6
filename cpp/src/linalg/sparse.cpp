#include "spacar/linalg/sparse.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace spacar {

void BlockMatrix::reset(int rows, int cols) {
  rows_.clear();
  cols_.clear();
  row_start_.assign(1, 0);
  col_start_.assign(1, 0);
  entry_start_.assign(1, 0);
  value_.clear();
  local_.clear();
  local_transposed_.clear();
  A_.resize(rows, cols);
}

int BlockMatrix::add_block(const std::vector<int>& rows, const std::vector<int>& cols) {
  rows_.insert(rows_.end(), rows.begin(), rows.end());
  cols_.insert(cols_.end(), cols.begin(), cols.end());
  row_start_.push_back(static_cast<int>(rows_.size()));
  col_start_.push_back(static_cast<int>(cols_.size()));
  return static_cast<int>(row_start_.size()) - 2;
}

// The pattern and every block entry's value position in O(entries), column by column, from a
// counting sort of the blocks' rows and of the blocks themselves by column (triplets sorted by
// Eigen and a binary search per entry took 40 % of the construction of a Simulation). A block
// stores its entries (rows and columns ≥ 0) column by column: entry (i, j) is value
// [slot(j) · stored rows + place of i among the stored rows].
void BlockMatrix::finalize() {
  const int n_rows = rows(), n_cols = cols();
  const int n_blocks = static_cast<int>(row_start_.size()) - 1;
  struct Ref {
    int block, slot;  // the block, and the place of its local column among its stored columns
  };
  // Each block's stored local rows (stored[stored_start[k] ...]), and per column the count of
  // rows and of (block, slot) pairs; each block's first entry.
  std::vector<int> stored, stored_start(n_blocks + 1, 0);
  std::vector<int> row_start(n_cols + 1, 0), ref_start(n_cols + 1, 0);
  stored.reserve(rows_.size());
  entry_start_.assign(n_blocks + 1, 0);
  for (int k = 0; k < n_blocks; ++k) {
    for (int i = 0; i < n_local_rows(k); ++i)
      if (rows_[row_start_[k] + i] >= 0) stored.push_back(i);
    stored_start[k + 1] = static_cast<int>(stored.size());
    const int n_own = stored_start[k + 1] - stored_start[k];
    int n_cols_stored = 0;
    for (int j = col_start_[k]; j < col_start_[k + 1]; ++j)
      if (const int c = cols_[j]; c >= 0) {
        row_start[c + 1] += n_own;
        ++ref_start[c + 1];
        ++n_cols_stored;
      }
    entry_start_[k + 1] = entry_start_[k] + n_own * n_cols_stored;
  }
  // Counts (in [c + 1]) to offsets.
  std::partial_sum(row_start.begin(), row_start.end(), row_start.begin());
  std::partial_sum(ref_start.begin(), ref_start.end(), ref_start.begin());
  std::vector<int> rows_in(row_start.back());
  std::vector<Ref> refs(ref_start.back());
  std::vector<int> row_fill(row_start.begin(), row_start.end() - 1), ref_fill(ref_start.begin(), ref_start.end() - 1);
  value_.assign(entry_start_.back(), 0);
  local_.assign(entry_start_.back(), 0);
  local_transposed_.assign(entry_start_.back(), 0);
  for (int k = 0; k < n_blocks; ++k) {
    const int* rows = rows_.data() + row_start_[k];
    const int nr = n_local_rows(k), nc = col_start_[k + 1] - col_start_[k];
    const int* own = stored.data() + stored_start[k];
    const int n_own = stored_start[k + 1] - stored_start[k];
    int slot = 0;
    for (int j = 0; j < nc; ++j) {
      const int c = cols_[col_start_[k] + j];
      if (c < 0) continue;
      for (int a = 0; a < n_own; ++a) {
        const int i = own[a], e = entry_start_[k] + slot * n_own + a;
        rows_in[row_fill[c]++] = rows[i];
        local_[e] = i + j * nr;
        local_transposed_[e] = j + i * nc;
      }
      refs[ref_fill[c]++] = {k, slot++};
    }
  }
  // The compressed pattern: each column's rows sorted, duplicates (blocks that overlap) merged.
  A_.resize(n_rows, n_cols);
  A_.resizeNonZeros(static_cast<Eigen::Index>(rows_in.size()));  // an upper bound, trimmed below
  int* outer = A_.outerIndexPtr();
  int* inner = A_.innerIndexPtr();
  int nnz = 0;
  outer[0] = 0;
  for (int c = 0; c < n_cols; ++c) {
    const auto first = rows_in.begin() + row_start[c], last = rows_in.begin() + row_start[c + 1];
    std::sort(first, last);
    nnz = static_cast<int>(std::copy(first, std::unique(first, last), inner + nnz) - inner);
    outer[c + 1] = nnz;
  }
  A_.resizeNonZeros(nnz);
  std::fill(A_.valuePtr(), A_.valuePtr() + nnz, 0.0);
  // Value positions: per column a table row → position, read by the blocks in that column.
  std::vector<int> position(n_rows, -1);
  for (int c = 0; c < n_cols; ++c) {
    for (int p = outer[c]; p < outer[c + 1]; ++p) position[inner[p]] = p;
    for (int q = ref_start[c]; q < ref_start[c + 1]; ++q) {
      const int k = refs[q].block;
      const int* rows = rows_.data() + row_start_[k];
      const int* own = stored.data() + stored_start[k];
      const int n_own = stored_start[k + 1] - stored_start[k];
      int* value = value_.data() + entry_start_[k] + refs[q].slot * n_own;
      for (int a = 0; a < n_own; ++a) value[a] = position[rows[own[a]]];
    }
  }
}

void BlockMatrix::set_zero() {
  // memset, not std::fill: GCC writes the doubles one by one otherwise (4 % of a static solve).
  if (A_.nonZeros() > 0) std::memset(A_.valuePtr(), 0, sizeof(double) * static_cast<size_t>(A_.nonZeros()));
}

void BlockMatrix::add(int id, const Eigen::MatrixXd& local) {
  double* v = A_.valuePtr();
  const double* l = local.data();
  for (int t = entry_start_[id]; t < entry_start_[id + 1]; ++t) v[value_[t]] += l[local_[t]];
}

void BlockMatrix::add_value(int id, int a, int b, double v) {
  const int entry = a + b * n_local_rows(id);
  for (int t = entry_start_[id]; t < entry_start_[id + 1]; ++t)
    if (local_[t] == entry) A_.valuePtr()[value_[t]] += v;
}

void BlockMatrix::add_transposed(int id, const Eigen::MatrixXd& local) {
  double* v = A_.valuePtr();
  const double* l = local.data();
  for (int t = entry_start_[id]; t < entry_start_[id + 1]; ++t) v[value_[t]] += l[local_transposed_[t]];
}

void LinearSolver::analyze(const Eigen::SparseMatrix<double>& A) {
  n_ = static_cast<int>(A.rows());
  lu_.analyze(A);
}

bool LinearSolver::factorize(const Eigen::SparseMatrix<double>& A) { return lu_.factorize(A); }

void LinearSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  x.resize(n_);
  lu_.solve(b.data(), x.data());
}

void LinearSolver::solve_transposed(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  x.resize(n_);
  lu_.solve_transposed(b.data(), x.data());
}

void LinearSolver::solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const {
  x.resize(n_, b.cols());
  for (int j = 0; j < b.cols(); ++j) lu_.solve(b.col(j).data(), x.col(j).data());  // contiguous columns
}

}  // namespace spacar
