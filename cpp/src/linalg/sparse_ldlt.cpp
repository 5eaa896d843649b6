#include "spacar/linalg/sparse_ldlt.hpp"

#include <cmath>

#include "spacar/limits.hpp"

namespace spacar {

void SparseLDLT::analyze(const Eigen::SparseMatrix<double>& A, const std::vector<int>& order) {
  n_ = static_cast<int>(A.rows());
  order_ = order;
  std::vector<int> step(n_);
  for (int k = 0; k < n_; ++k) step[order_[k]] = k;
  // C's columns: the entries of A's column order[k] whose rows come at steps ≤ k.
  Cp_.assign(1, 0);
  Ci_.clear();
  Cpos_.clear();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  for (int k = 0; k < n_; ++k) {
    const int col = order_[k];
    for (int p = outer[col]; p < outer[col + 1]; ++p) {
      const int s = step[inner[p]];
      if (s > k) continue;
      Ci_.push_back(s);
      Cpos_.push_back(p);
    }
    Cp_.push_back(static_cast<int>(Ci_.size()));
  }
  // Elimination tree and the number of entries of each column of L (LDL's symbolic pass).
  parent_.assign(n_, -1);
  flag_.assign(n_, -1);
  count_.assign(n_, 0);
  for (int k = 0; k < n_; ++k) {
    flag_[k] = k;
    for (int p = Cp_[k]; p < Cp_[k + 1]; ++p) {
      for (int i = Ci_[p]; i < k && flag_[i] != k; i = parent_[i]) {
        if (parent_[i] == -1) parent_[i] = k;
        ++count_[i];
        flag_[i] = k;
      }
    }
  }
  Lp_.assign(n_ + 1, 0);
  for (int k = 0; k < n_; ++k) Lp_[k + 1] = Lp_[k] + count_[k];
  Li_.assign(Lp_[n_], 0);
  Lx_.assign(Lp_[n_], 0.0);
  D_.assign(n_, 0.0);
  y_.assign(n_, 0.0);
  pattern_.assign(n_, 0);
}

bool SparseLDLT::factorize(const Eigen::SparseMatrix<double>& A, double tiny) {
  const double* values = A.valuePtr();
  negative_ = perturbed_ = 0;
  std::fill(count_.begin(), count_.end(), 0);  // entries of each column of L so far
  for (int k = 0; k < n_; ++k) {
    if ((k & 1023) == 1023) check_thread_deadline("(in a sparse factorization)");
    // Row k of L: the nonzero pattern from the elimination tree, the values from the sparse
    // triangular solve L(0:k, 0:k) D y = C(0:k, k).
    int top = n_;
    flag_[k] = k;
    for (int p = Cp_[k]; p < Cp_[k + 1]; ++p) {
      int i = Ci_[p];
      y_[i] += values[Cpos_[p]];
      int len = 0;
      for (; flag_[i] != k; i = parent_[i]) {
        pattern_[len++] = i;
        flag_[i] = k;
      }
      while (len > 0) pattern_[--top] = pattern_[--len];
    }
    double d = y_[k];
    y_[k] = 0.0;
    for (; top < n_; ++top) {
      const int i = pattern_[top];
      const double yi = y_[i];
      y_[i] = 0.0;
      const int end = Lp_[i] + count_[i];
      for (int p = Lp_[i]; p < end; ++p) y_[Li_[p]] -= Lx_[p] * yi;
      const double l = yi / D_[i];
      d -= l * yi;
      Li_[end] = k;
      Lx_[end] = l;
      ++count_[i];
    }
    if (!std::isfinite(d)) {
      std::fill(y_.begin(), y_.end(), 0.0);
      return false;
    }
    if (std::abs(d) <= tiny) {
      d = d < 0.0 ? -tiny : tiny;
      ++perturbed_;
    }
    if (d < 0.0) ++negative_;
    D_[k] = d;
  }
  return true;
}

void SparseLDLT::solve(const double* b, double* x) const {
  double* y = y_.data();
  for (int k = 0; k < n_; ++k) y[k] = b[order_[k]];
  for (int j = 0; j < n_; ++j)
    for (int p = Lp_[j]; p < Lp_[j + 1]; ++p) y[Li_[p]] -= Lx_[p] * y[j];
  for (int k = 0; k < n_; ++k) y[k] /= D_[k];
  for (int j = n_ - 1; j >= 0; --j)
    for (int p = Lp_[j]; p < Lp_[j + 1]; ++p) y[j] -= Lx_[p] * y[Li_[p]];
  for (int k = 0; k < n_; ++k) {
    x[order_[k]] = y[k];
    y[k] = 0.0;  // the work vector is all zero between factorizations and solves
  }
}

}  // namespace spacar
