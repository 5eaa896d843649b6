#include "spacar/linalg/sparse.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace spacar {

void BlockMatrix::reset(int rows, int cols) {
  blocks_.clear();
  A_.resize(rows, cols);
}

int BlockMatrix::add_block(const std::vector<int>& rows, const std::vector<int>& cols) {
  blocks_.push_back({rows, cols, {}, {}, {}});
  return static_cast<int>(blocks_.size()) - 1;
}

// The pattern and every block entry's value position in O(entries), column by column, from a
// counting sort of the blocks' rows and of the blocks themselves by column (triplets sorted by
// Eigen and a binary search per entry took 40 % of the construction of a Simulation). A block
// stores its entries (rows and columns ≥ 0) column by column: entry (i, j) is value
// [slot(j) · stored rows + place of i among the stored rows].
void BlockMatrix::finalize() {
  const int n_rows = rows(), n_cols = cols();
  const int n_blocks = static_cast<int>(blocks_.size());
  struct Ref {
    int block, slot;  // the block, and the place of its local column among its stored columns
  };
  // Each block's stored local rows (stored[stored_start[k] ...]), and per column the count of
  // rows and of (block, slot) pairs.
  std::vector<int> stored, stored_start(n_blocks + 1, 0);
  std::vector<int> row_start(n_cols + 1, 0), ref_start(n_cols + 1, 0);
  for (int k = 0; k < n_blocks; ++k) {
    const Block& b = blocks_[k];
    for (int i = 0; i < static_cast<int>(b.rows.size()); ++i)
      if (b.rows[i] >= 0) stored.push_back(i);
    stored_start[k + 1] = static_cast<int>(stored.size());
    for (int c : b.cols)
      if (c >= 0) {
        row_start[c + 1] += stored_start[k + 1] - stored_start[k];
        ++ref_start[c + 1];
      }
  }
  // Counts (in [c + 1]) to offsets.
  std::partial_sum(row_start.begin(), row_start.end(), row_start.begin());
  std::partial_sum(ref_start.begin(), ref_start.end(), ref_start.begin());
  std::vector<int> rows_in(row_start.back());
  std::vector<Ref> refs(ref_start.back());
  std::vector<int> row_fill(row_start.begin(), row_start.end() - 1), ref_fill(ref_start.begin(), ref_start.end() - 1);
  for (int k = 0; k < n_blocks; ++k) {
    Block& b = blocks_[k];
    const int nr = static_cast<int>(b.rows.size()), nc = static_cast<int>(b.cols.size());
    const int* own = stored.data() + stored_start[k];
    const int n_own = stored_start[k + 1] - stored_start[k];
    const auto n_cols_stored = std::count_if(b.cols.begin(), b.cols.end(), [](int c) { return c >= 0; });
    b.local.resize(static_cast<size_t>(n_own) * n_cols_stored);
    b.local_transposed.resize(b.local.size());
    b.value.resize(b.local.size());
    int slot = 0;
    for (int j = 0; j < nc; ++j) {
      const int c = b.cols[j];
      if (c < 0) continue;
      for (int a = 0; a < n_own; ++a) {
        const int i = own[a], e = slot * n_own + a;
        rows_in[row_fill[c]++] = b.rows[i];
        b.local[e] = i + j * nr;
        b.local_transposed[e] = j + i * nc;
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
      Block& b = blocks_[refs[q].block];
      const int* own = stored.data() + stored_start[refs[q].block];
      const int n_own = stored_start[refs[q].block + 1] - stored_start[refs[q].block];
      int* value = b.value.data() + static_cast<size_t>(refs[q].slot) * n_own;
      for (int a = 0; a < n_own; ++a) value[a] = position[b.rows[own[a]]];
    }
  }
}

void BlockMatrix::set_zero() { std::fill(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), 0.0); }

void BlockMatrix::add(int id, const Eigen::MatrixXd& local) {
  const Block& b = blocks_[id];
  double* v = A_.valuePtr();
  const double* l = local.data();
  for (size_t t = 0; t < b.value.size(); ++t) v[b.value[t]] += l[b.local[t]];
}

void BlockMatrix::add_value(int id, int a, int b, double v) {
  const Block& k = blocks_[id];
  const int entry = a + b * static_cast<int>(k.rows.size());
  for (size_t t = 0; t < k.local.size(); ++t)
    if (k.local[t] == entry) A_.valuePtr()[k.value[t]] += v;
}

void BlockMatrix::add_transposed(int id, const Eigen::MatrixXd& local) {
  const Block& b = blocks_[id];
  double* v = A_.valuePtr();
  const double* l = local.data();
  for (size_t t = 0; t < b.value.size(); ++t) v[b.value[t]] += l[b.local_transposed[t]];
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
