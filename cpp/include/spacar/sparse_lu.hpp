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
  // Choose the column ordering from the pattern (once per pattern): the one of COLAMD and AMD on
  // A + Aᵀ that gives the fewer nonzeros in the factors of A's values at the first factorization.
  void analyze(const Eigen::SparseMatrix<double>& A);
  // Factorize A (same pattern as in analyze); false if A is numerically singular: a pivot below
  // kSingular times the largest entry of A, or non-finite values.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  // x = A⁻¹ b and x = A⁻ᵀ b; x may not alias b. NaN if the last factorization failed.
  void solve(const double* b, double* x) const;
  void solve_transposed(const double* b, double* x) const;

  int size() const { return n_; }
  int factor_nonzeros() const { return static_cast<int>(Li_.size() + Ui_.size()) + n_; }
  // Pivot choices made (not replays); the first factorization counts one per ordering tried.
  int pivotings() const { return pivotings_; }

  static constexpr double kSingular = 1e-13;
  // A replayed pivot must be at least this fraction of the largest entry of its column of L.
  static constexpr double kReplayThreshold = 1e-3;
  // Partial pivoting: keep the diagonal entry of the ordered matrix (symmetric orderings) if it
  // is at least this fraction of the largest candidate.
  static constexpr double kDiagonalPreference = 0.1;

 private:
  bool compute(const Eigen::SparseMatrix<double>& A);
  // False if A is singular in this order, or once the factors have more than max_nonzeros.
  bool factorize_pivoting(const Eigen::SparseMatrix<double>& A, const std::vector<int>& order,
                          int max_nonzeros = std::numeric_limits<int>::max());
  bool refuse_solve(double* x) const;
  bool replay(const Eigen::SparseMatrix<double>& A);
  int reach(const Eigen::SparseMatrix<double>& A, int col);

  int n_ = 0;
  double amax_ = 0.0;
  bool have_pivots_ = false;  // a pivot sequence to replay
  bool valid_ = false;        // factors of the last factorized matrix, for solves
  int pivotings_ = 0;
  std::vector<int> colamd_, amd_;  // candidate column orderings, until the first factorization
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
