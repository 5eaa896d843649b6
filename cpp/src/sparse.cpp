#include "spacar/sparse.hpp"

#include <algorithm>
#include <cmath>

namespace spacar {

void BlockMatrix::reset(int rows, int cols) {
  blocks_.clear();
  A_.resize(rows, cols);
}

int BlockMatrix::add_block(const std::vector<int>& rows, const std::vector<int>& cols) {
  blocks_.push_back({rows, cols, {}});
  return static_cast<int>(blocks_.size()) - 1;
}

void BlockMatrix::finalize() {
  std::vector<Eigen::Triplet<double>> entries;
  for (const Block& b : blocks_)
    for (int r : b.rows)
      for (int c : b.cols)
        if (r >= 0 && c >= 0) entries.emplace_back(r, c, 0.0);
  A_.setFromTriplets(entries.begin(), entries.end());
  A_.makeCompressed();
  const int* outer = A_.outerIndexPtr();
  const int* inner = A_.innerIndexPtr();
  for (Block& b : blocks_) {
    const int nr = static_cast<int>(b.rows.size()), nc = static_cast<int>(b.cols.size());
    b.index.assign(nr * nc, -1);
    for (int j = 0; j < nc; ++j) {
      const int c = b.cols[j];
      if (c < 0) continue;
      for (int i = 0; i < nr; ++i) {
        const int r = b.rows[i];
        if (r < 0) continue;
        const int* pos = std::lower_bound(inner + outer[c], inner + outer[c + 1], r);
        b.index[i + j * nr] = static_cast<int>(pos - inner);
      }
    }
  }
}

void BlockMatrix::set_zero() { std::fill(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), 0.0); }

void BlockMatrix::add(int id, const Eigen::MatrixXd& local) {
  const Block& b = blocks_[id];
  double* v = A_.valuePtr();
  const int nr = static_cast<int>(b.rows.size()), nc = static_cast<int>(b.cols.size());
  for (int j = 0; j < nc; ++j)
    for (int i = 0; i < nr; ++i) {
      const int k = b.index[i + j * nr];
      if (k >= 0) v[k] += local(i, j);
    }
}

void BlockMatrix::add_transposed(int id, const Eigen::MatrixXd& local) {
  const Block& b = blocks_[id];
  double* v = A_.valuePtr();
  const int nr = static_cast<int>(b.rows.size()), nc = static_cast<int>(b.cols.size());
  for (int j = 0; j < nc; ++j)
    for (int i = 0; i < nr; ++i) {
      const int k = b.index[i + j * nr];
      if (k >= 0) v[k] += local(j, i);
    }
}

void LinearSolver::analyze(const Eigen::SparseMatrix<double>& A) {
  n_ = static_cast<int>(A.rows());
  dense_ = n_ <= kDenseLimit;
  if (dense_) {
    dense_matrix_.setZero(n_, n_);
  } else {
    sparse_lu_.analyzePattern(A);
  }
}

bool LinearSolver::factorize(const Eigen::SparseMatrix<double>& A) {
  if (n_ == 0) return true;
  if (dense_) {
    dense_matrix_.setZero();
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it) dense_matrix_(it.row(), c) = it.value();
    dense_lu_.compute(dense_matrix_);
    // Singular: a pivot that is tiny against the largest entry (σ_min ≤ n min|u_kk|). Eigen's
    // condition estimate would be sharper but allocates and costs a few solves per call.
    const double amax = dense_matrix_.cwiseAbs().maxCoeff();
    const double pmin = dense_lu_.matrixLU().diagonal().cwiseAbs().minCoeff();
    return std::isfinite(pmin) && amax > 0.0 && pmin > 1e-13 * amax;
  }
  // Overflowed entries (a trial state far out of range) would pass as a "successful" factorization.
  if (!Eigen::Map<const Eigen::VectorXd>(A.valuePtr(), A.nonZeros()).allFinite()) return false;
  sparse_lu_.factorize(A);
  return sparse_lu_.info() == Eigen::Success;
}

void LinearSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (n_ == 0) return;
  if (dense_) x = dense_lu_.solve(b);
  else x = sparse_lu_.solve(b);
}

void LinearSolver::solve_transposed(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  if (n_ == 0) return;
  if (dense_) x = dense_lu_.transpose().solve(b);
  else x = sparse_lu_.transpose().solve(b);
}

void LinearSolver::solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const {
  if (n_ == 0) return;
  if (dense_) x = dense_lu_.solve(b);
  else x = sparse_lu_.solve(b);
}

}  // namespace spacar
