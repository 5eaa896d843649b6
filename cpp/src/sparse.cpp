#include "spacar/sparse.hpp"

#include <algorithm>
#include <cmath>

namespace spacar {

void BlockMatrix::reset(int rows, int cols) {
  blocks_.clear();
  A_.resize(rows, cols);
}

int BlockMatrix::add_block(const std::vector<int>& rows, const std::vector<int>& cols) {
  blocks_.push_back({rows, cols, {}, {}, {}});
  return static_cast<int>(blocks_.size()) - 1;
}

void BlockMatrix::finalize() {
  std::vector<Eigen::Triplet<double>> entries;
  size_t total = 0;
  for (const Block& b : blocks_) total += b.rows.size() * b.cols.size();
  entries.reserve(total);
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
    for (auto* v : {&b.value, &b.local, &b.local_transposed}) {
      v->clear();
      v->reserve(static_cast<size_t>(nr) * nc);
    }
    for (int j = 0; j < nc; ++j) {
      const int c = b.cols[j];
      if (c < 0) continue;
      for (int i = 0; i < nr; ++i) {
        const int r = b.rows[i];
        if (r < 0) continue;
        const int* pos = std::lower_bound(inner + outer[c], inner + outer[c + 1], r);
        b.value.push_back(static_cast<int>(pos - inner));
        b.local.push_back(i + j * nr);
        b.local_transposed.push_back(j + i * nc);
      }
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
