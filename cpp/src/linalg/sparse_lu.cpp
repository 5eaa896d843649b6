#include "spacar/linalg/sparse_lu.hpp"

#include "spacar/limits.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

namespace spacar {

namespace {

using Perm = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;

// Step → column orders. Eigen's COLAMD functor returns column → step, its AMD functor step →
// column (the conventions of SparseLU and SimplicialLDLT).
std::vector<int> colamd_order(const Eigen::SparseMatrix<double>& A) {
  Eigen::SparseMatrix<double> B = A;
  Perm perm;
  Eigen::COLAMDOrdering<int>()(B, perm);
  std::vector<int> q(A.cols());
  for (int c = 0; c < A.cols(); ++c) q[perm.indices()[c]] = c;
  return q;
}

std::vector<int> amd_order(const Eigen::SparseMatrix<double>& A) {
  Perm perm;
  Eigen::AMDOrdering<int>()(A, perm);
  return std::vector<int>(perm.indices().data(), perm.indices().data() + A.cols());
}

}  // namespace

void SparseLU::analyze(const Eigen::SparseMatrix<double>& A) {
  n_ = static_cast<int>(A.rows());
  have_pivots_ = false;
  valid_ = n_ == 0;
  w_.assign(n_, 0.0);
  stack_.assign(2 * n_, 0);
  mark_.assign(n_, 0);
  if (n_ == 0) return;
  first_ = true;
  replays_ = 0;
  amd_tried_ = false;
}

// Rows reachable from the pattern of column col of A in the graph of L (row i → rows of the
// column of L whose pivot it is), in topological order in stack_[top, n). Depth first, without
// recursion; stack_[n, 2n) holds the positions reached in each column of the path.
int SparseLU::reach(const Eigen::SparseMatrix<double>& A, int col) {
  int top = n_;
  int* pos = stack_.data() + n_;
  for (Eigen::SparseMatrix<double>::InnerIterator it(A, col); it; ++it) {
    const int start = static_cast<int>(it.row());
    if (mark_[start]) continue;
    // path[0..head] is the current path, kept in stack_ below `top` (disjoint from the output).
    int head = 0;
    stack_[0] = start;
    while (head >= 0) {
      const int i = stack_[head];
      const int s = pinv_[i];
      if (!mark_[i]) {
        mark_[i] = 1;
        pos[head] = s < 0 ? 0 : Lp_[s];
      }
      bool done = true;
      const int end = s < 0 ? 0 : Lp_[s + 1];
      for (int p = pos[head]; p < end; ++p) {
        const int r = Li_[p];
        if (mark_[r]) continue;
        pos[head] = p + 1;
        stack_[++head] = r;
        done = false;
        break;
      }
      if (done) {
        --head;
        stack_[--top] = i;
      }
    }
  }
  for (int p = top; p < n_; ++p) mark_[stack_[p]] = 0;
  return top;
}

bool SparseLU::factorize_pivoting(const Eigen::SparseMatrix<double>& A, const std::vector<int>& order,
                                  int max_nonzeros) {
  ++pivotings_;
  q_ = order;
  pinv_.assign(n_, -1);
  Lp_.assign(1, 0);
  Up_.assign(1, 0);
  Li_.clear();
  Lx_.clear();
  Ui_.clear();
  Ux_.clear();
  Uinv_.clear();
  // Room for the factors of a modest fill (twice A's nonzeros each), so that they do not grow
  // entry by entry in the first factorization.
  const size_t room = 2 * static_cast<size_t>(A.nonZeros());
  for (auto* v : {&Li_, &Ui_}) v->reserve(room);
  for (auto* v : {&Lx_, &Ux_}) v->reserve(room);
  Lp_.reserve(n_ + 1);
  Up_.reserve(n_ + 1);
  Uinv_.reserve(n_);
  std::fill(w_.begin(), w_.end(), 0.0);
  for (int k = 0; k < n_; ++k) {
    // A large system's first factorization (or a singular one's, whose fill can grow without
    // bound before a zero pivot shows) is the one long computation between the integrator's steps.
    if ((k & 255) == 255) check_thread_deadline("(in a sparse factorization)");
    const int col = q_[k];
    const int top = reach(A, col);
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, col); it; ++it) w_[it.row()] = it.value();
    // Sparse triangular solve with the columns of L so far, in topological order.
    for (int p = top; p < n_; ++p) {
      const int i = stack_[p];
      const int s = pinv_[i];
      if (s < 0) continue;
      const double xi = w_[i];
      for (int t = Lp_[s]; t < Lp_[s + 1]; ++t) w_[Li_[t]] -= Lx_[t] * xi;
    }
    // Pivot: the largest candidate, or the diagonal of the ordered matrix if it is not much smaller.
    int ipiv = -1;
    double best = -1.0;
    for (int p = top; p < n_; ++p) {
      const int i = stack_[p];
      if (pinv_[i] >= 0) continue;
      const double a = std::abs(w_[i]);
      if (a > best || std::isnan(a)) {
        best = a;
        ipiv = i;
      }
    }
    if (ipiv < 0 || !(best > kSingular * amax_) || !std::isfinite(best)) {
      std::fill(w_.begin(), w_.end(), 0.0);
      have_pivots_ = false;
      return false;
    }
    const double diagonal = pinv_[col] < 0 ? std::abs(w_[col]) : 0.0;
    if (diagonal >= kDiagonalPreference * best && diagonal > kSingular * amax_) ipiv = col;
    const double pivot = w_[ipiv];
    double total = 0.0;  // of the column's magnitudes: not finite if any entry overflowed or is NaN
    for (int p = top; p < n_; ++p) {
      const int i = stack_[p];
      if (pinv_[i] >= 0) {
        Ui_.push_back(pinv_[i]);
        Ux_.push_back(w_[i]);
        total += std::abs(w_[i]);
      } else if (i != ipiv) {
        Li_.push_back(i);
        Lx_.push_back(w_[i] / pivot);
        total += std::abs(Lx_.back());
      }
      w_[i] = 0.0;
    }
    if (!std::isfinite(total)) {
      have_pivots_ = false;
      return false;
    }
    if (static_cast<int>(Li_.size() + Ui_.size()) + k + 1 > max_nonzeros) {
      have_pivots_ = false;
      return false;
    }
    Uinv_.push_back(1.0 / pivot);
    pinv_[ipiv] = k;
    Lp_.push_back(static_cast<int>(Li_.size()));
    Up_.push_back(static_cast<int>(Ui_.size()));
  }
  // Rows of L as steps; columns of U sorted by step, the order of the replay.
  for (int& i : Li_) i = pinv_[i];
  auto& column = sort_space_;
  for (int k = 0; k < n_; ++k) {
    column.clear();
    for (int p = Up_[k]; p < Up_[k + 1]; ++p) column.emplace_back(Ui_[p], Ux_[p]);
    std::sort(column.begin(), column.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (int p = Up_[k], j = 0; p < Up_[k + 1]; ++p, ++j) {
      Ui_[p] = column[j].first;
      Ux_[p] = column[j].second;
    }
  }
  // Where A's entries go in the replay.
  Ap_.assign(1, 0);
  Ai_.clear();
  Apos_.clear();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  for (int k = 0; k < n_; ++k) {
    for (int p = outer[q_[k]]; p < outer[q_[k] + 1]; ++p) {
      Apos_.push_back(p);
      Ai_.push_back(pinv_[inner[p]]);
    }
    Ap_.push_back(static_cast<int>(Apos_.size()));
  }
  have_pivots_ = true;
  return true;
}

bool SparseLU::replay(const Eigen::SparseMatrix<double>& A) {
  const double* Ax = A.valuePtr();
  double* w = w_.data();
  for (int k = 0; k < n_; ++k) {
    for (int p = Ap_[k]; p < Ap_[k + 1]; ++p) w[Ai_[p]] = Ax[Apos_[p]];
    double total = 0.0;  // of the column's magnitudes: not finite if any entry overflowed or is NaN
    for (int p = Up_[k]; p < Up_[k + 1]; ++p) {
      const int s = Ui_[p];
      const double xs = w[s];
      Ux_[p] = xs;
      total += std::abs(xs);
      w[s] = 0.0;
      for (int t = Lp_[s]; t < Lp_[s + 1]; ++t) w[Li_[t]] -= Lx_[t] * xs;
    }
    const double pivot = w[k];
    w[k] = 0.0;
    double column_max = 0.0;
    for (int t = Lp_[k]; t < Lp_[k + 1]; ++t) {
      const double a = std::abs(w[Li_[t]]);
      column_max = std::max(column_max, a);
      total += a;
    }
    const double a = std::abs(pivot);
    total += a;
    if (!(a > kSingular * amax_) || a < kReplayThreshold * column_max || !std::isfinite(total)) {
      std::fill(w_.begin(), w_.end(), 0.0);
      return false;
    }
    const double inv = 1.0 / pivot;
    Uinv_[k] = inv;
    for (int t = Lp_[k]; t < Lp_[k + 1]; ++t) {
      Lx_[t] = w[Li_[t]] * inv;
      w[Li_[t]] = 0.0;
    }
  }
  return true;
}

void SparseLU::adopt_pivots(const SparseLU& other, const Eigen::SparseMatrix<double>& A) {
  if (!first_ || !other.have_pivots_ || other.n_ != n_ || A.rows() != n_ ||
      static_cast<size_t>(A.nonZeros()) != other.Apos_.size())
    return;
  *this = other;
  pivotings_ = 0;  // none chosen here
  replays_ = 0;
}

bool SparseLU::factorize(const Eigen::SparseMatrix<double>& A) {
  valid_ = compute(A);
  return valid_;
}

bool SparseLU::compute(const Eigen::SparseMatrix<double>& A) {
  if (n_ == 0) return true;
  // Overflowed entries (a trial state far out of range) would pass as a "successful"
  // factorization: refuse NaN and infinity. Two vectorized passes: maxCoeff may skip a NaN
  // (Eigen 3.3 has no NaN-propagating one), and Σ 0·a is 0 unless an entry is NaN or infinite.
  const Eigen::Map<const Eigen::ArrayXd> values(A.valuePtr(), A.nonZeros());
  amax_ = values.size() ? values.abs().maxCoeff() : 0.0;
  if (!std::isfinite(amax_) || (values * 0.0).sum() != 0.0) return false;
  if (have_pivots_ && replay(A)) {
    if (!amd_tried_ && ++replays_ >= kReplaysBeforeTrial) return try_amd(A);
    return true;
  }
  if (first_) {  // the first factorization, in COLAMD's order (found only now: see adopt_pivots)
    if (!factorize_pivoting(A, colamd_order(A))) {  // singular in COLAMD's order: AMD's
      if (!factorize_pivoting(A, amd_order(A))) return false;  // both again at the next factorization
      amd_tried_ = true;
    }
    first_ = false;
    return true;
  }
  return factorize_pivoting(A, q_);
}

bool SparseLU::try_amd(const Eigen::SparseMatrix<double>& A) {
  amd_tried_ = true;
  // The trial factorizes into the members: keep the replayed factors of A to return to.
  auto factors = std::make_tuple(q_, pinv_, Lp_, Li_, Lx_, Up_, Ui_, Ux_, Uinv_, Ap_, Ai_, Apos_);
  if (factorize_pivoting(A, amd_order(A), factor_nonzeros() - 1)) return true;
  std::tie(q_, pinv_, Lp_, Li_, Lx_, Up_, Ui_, Ux_, Uinv_, Ap_, Ai_, Apos_) = std::move(factors);
  have_pivots_ = true;
  return true;
}

namespace {
// +1 for an even permutation, −1 for an odd one (by its cycles).
int parity(const std::vector<int>& perm) {
  std::vector<char> seen(perm.size(), 0);
  int sign = 1;
  for (size_t i = 0; i < perm.size(); ++i) {
    if (seen[i]) continue;
    size_t length = 0;
    for (size_t j = i; !seen[j]; j = static_cast<size_t>(perm[j])) {
      seen[j] = 1;
      ++length;
    }
    if (length % 2 == 0) sign = -sign;
  }
  return sign;
}
}  // namespace

int SparseLU::sign_determinant() const {
  if (!valid_) return 0;
  int sign = parity(q_) * parity(pinv_);
  for (double u : Uinv_)
    if (u < 0.0) sign = -sign;
  return sign;
}

// Without valid factors (none yet, or the last factorization failed part way) the solution is
// NaN: the factors and permutations are incomplete then.
bool SparseLU::refuse_solve(double* x) const {
  if (valid_) return false;
  std::fill(x, x + n_, std::numeric_limits<double>::quiet_NaN());
  return true;
}

void SparseLU::solve(const double* b, double* x) const {
  if (refuse_solve(x)) return;
  double* y = w_.data();
  for (int i = 0; i < n_; ++i) y[pinv_[i]] = b[i];
  for (int k = 0; k < n_; ++k) {
    const double yk = y[k];
    for (int t = Lp_[k]; t < Lp_[k + 1]; ++t) y[Li_[t]] -= Lx_[t] * yk;
  }
  for (int k = n_ - 1; k >= 0; --k) {
    const double yk = y[k] * Uinv_[k];
    y[k] = yk;
    for (int p = Up_[k]; p < Up_[k + 1]; ++p) y[Ui_[p]] -= Ux_[p] * yk;
  }
  for (int k = 0; k < n_; ++k) {
    x[q_[k]] = y[k];
    y[k] = 0.0;
  }
}

void SparseLU::solve_transposed(const double* b, double* x) const {
  if (refuse_solve(x)) return;
  // Aᵀ = Q Uᵀ Lᵀ P.
  double* y = w_.data();
  for (int k = 0; k < n_; ++k) {
    double v = b[q_[k]];
    for (int p = Up_[k]; p < Up_[k + 1]; ++p) v -= Ux_[p] * y[Ui_[p]];
    y[k] = v * Uinv_[k];
  }
  for (int k = n_ - 1; k >= 0; --k) {
    double v = y[k];
    for (int t = Lp_[k]; t < Lp_[k + 1]; ++t) v -= Lx_[t] * y[Li_[t]];
    y[k] = v;
  }
  for (int i = 0; i < n_; ++i) x[i] = y[pinv_[i]];
  std::fill(w_.begin(), w_.end(), 0.0);
}

}  // namespace spacar
