// Sparse LU with a pivot sequence that is reused across factorizations (refactorization, as in
// KLU). The matrices of a mechanism keep their pattern and change their values slowly along a
// motion: the rows chosen as pivots at one state stay good pivots at the next, so after one
// factorization with partial pivoting every further one replays the same elimination on the
// new values, with the fill pattern, the permutations and the order of operations computed
// once. Each replayed pivot is checked against its column; a poor one (the motion has changed
// which rows are large) makes that factorization choose its pivots again.
//
// Left-looking elimination (Gilbert and Peierls): column k of L and U comes from one sparse
// triangular solve with the columns of L found so far. With the fixed pivot order, the columns
// of U are visited in increasing pivot order, a valid topological order of that solve, so a
// refactorization needs no graph search: it costs only the floating-point operations of the
// factors (for a chain of links: linear in the number of links).
#pragma once

#include <Eigen/Sparse>
#include <limits>
#include <utility>
#include <vector>

namespace spacar {

class SparseLU {
 public:
  // Prepare for matrices of A's pattern: the column ordering starts as COLAMD's (computed at the
  // first factorization). Once its factors
  // have been replayed kReplaysBeforeTrial times, AMD's ordering of A + Aᵀ is tried once and kept
  // if its factors are sparser: a short run (a handful of factorizations) does not pay for the
  // trial, a long one gains from the sparser factors at every replay.
  void analyze(const Eigen::SparseMatrix<double>& A);
  // Factorize A (same pattern as in analyze); false if A is numerically singular: a pivot below
  // kSingular times the largest entry of A, or non-finite values.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  // x = A⁻¹ b and x = A⁻ᵀ b; x may not alias b. NaN if the last factorization failed.
  void solve(const double* b, double* x) const;
  void solve_transposed(const double* b, double* x) const;

  int size() const { return n_; }
  // Take the pivot sequence (ordering, fill pattern, factors) of another factorization of a
  // matrix of A's pattern, if this one has not factorized yet: its first factorization of A is
  // then a replay, not a search for pivots (the velocity block of a holonomic system is the
  // position block, factorized first in the assembly). The caller guarantees the pattern; a
  // different size or number of entries is refused here.
  void adopt_pivots(const SparseLU& other, const Eigen::SparseMatrix<double>& A);
  int factor_nonzeros() const { return static_cast<int>(Li_.size() + Ui_.size()) + n_; }
  // The sign of det A from the last successful factorization: the parities of the two
  // permutations times the signs of U's diagonal.
  int sign_determinant() const;
  // Pivot choices made (not replays), one per ordering tried.
  int pivotings() const { return pivotings_; }

  static constexpr double kSingular = 1e-13;
  // A replayed pivot must be at least this fraction of the largest entry of its column of L.
  static constexpr double kReplayThreshold = 1e-3;
  // Partial pivoting: keep the diagonal entry of the ordered matrix (symmetric orderings) if it
  // is at least this fraction of the largest candidate.
  static constexpr double kDiagonalPreference = 0.1;
  // Replays before AMD's ordering is tried: a factorization with pivoting, its graph searches and
  // the trial's own costs as much as tens of replays.
  static constexpr int kReplaysBeforeTrial = 32;

 private:
  bool compute(const Eigen::SparseMatrix<double>& A);
  // False if A is singular in this order, or once the factors have more than max_nonzeros.
  bool factorize_pivoting(const Eigen::SparseMatrix<double>& A, const std::vector<int>& order,
                          int max_nonzeros = std::numeric_limits<int>::max());
  bool refuse_solve(double* x) const;
  // Factorize A in AMD's order (stopped once fuller than the current factors), kept if sparser;
  // else the replayed factors of A are restored. The trial can stop early: a constraint matrix can fill
  // densely in AMD's order (a 100-link chain's equations of motion: 184 672 nonzeros against
  // COLAMD's 9540).
  bool try_amd(const Eigen::SparseMatrix<double>& A);
  bool replay(const Eigen::SparseMatrix<double>& A);
  int reach(const Eigen::SparseMatrix<double>& A, int col);

  int n_ = 0;
  double amax_ = 0.0;
  bool have_pivots_ = false;  // a pivot sequence to replay
  bool valid_ = false;        // factors of the last factorized matrix, for solves
  int pivotings_ = 0;
  bool first_ = false;             // no pivot sequence yet: the next factorization orders the columns
  int replays_ = 0;                // successful replays, until AMD's ordering is tried
  bool amd_tried_ = false;
  std::vector<int> q_;             // step k eliminates column q_[k] of A
  std::vector<int> pinv_;          // row i of A is the pivot of step pinv_[i]
  // L (unit diagonal, not stored) and U by columns, rows as step indices; the rows of a column of
  // U are increasing. U's diagonal is kept as reciprocals: the solves multiply, and a division
  // in their chain of dependent rows would cost its latency at every row.
  std::vector<int> Lp_, Li_, Up_, Ui_;
  std::vector<double> Lx_, Ux_, Uinv_;
  // For the replay: where each entry of A goes in the work vector (its pivot step), column by
  // column in the order of q_.
  std::vector<int> Ap_, Ai_, Apos_;
  // Work space of size n (values) and 2n (graph search), never reallocated after analyze.
  mutable std::vector<double> w_;
  std::vector<int> stack_, mark_;
  std::vector<std::pair<int, double>> sort_space_;  // a column of U being sorted
};

}  // namespace spacar
