// Sparse assembly with a fixed pattern, and its LU factorization. The constraint blocks and the
// equations of motion of a mechanism are assembled from element blocks whose places never
// change: the pattern is built once per System, and every evaluation only writes values (no
// allocation in the step loop).
#pragma once

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <vector>

#include "spacar/linalg/sparse_lu.hpp"

namespace spacar {

class BlockMatrix {
 public:
  // Start a matrix of the given size; blocks are registered next, then finalize().
  void reset(int rows, int cols);
  // Register a block: rows[a] and cols[b] are the global row and column of local entry (a, b);
  // −1 leaves that local row or column out. Returns the block id.
  int add_block(const std::vector<int>& rows, const std::vector<int>& cols);
  // Build the compressed pattern and the value position of every block entry.
  void finalize();

  void set_zero();
  // Add local (rows.size() x cols.size()) to the block, or its transpose (cols x rows) read as
  // local(b, a).
  void add(int id, const Eigen::MatrixXd& local);
  void add_transposed(int id, const Eigen::MatrixXd& local);
  // Add v to local entry (a, b), if it is stored.
  void add_value(int id, int a, int b, double v);

  const Eigen::SparseMatrix<double>& matrix() const { return A_; }
  int rows() const { return static_cast<int>(A_.rows()); }
  int cols() const { return static_cast<int>(A_.cols()); }

 private:
  // The blocks in flat arrays (one allocation per array, not five per block: a large model's
  // set-up registers thousands of blocks): block k's global rows are rows_[row_start_[k] ...],
  // its columns cols_[col_start_[k] ...], and its stored entries (rows and columns ≥ 0) the
  // lists value_, local_, local_transposed_ from entry_start_[k]: the value position, the local
  // entry (column-major) and the local entry of the transpose; add() runs down them without tests.
  int n_local_rows(int k) const { return row_start_[k + 1] - row_start_[k]; }
  std::vector<int> rows_, cols_, row_start_{0}, col_start_{0};
  std::vector<int> value_, local_, local_transposed_, entry_start_{0};
  Eigen::SparseMatrix<double> A_;
};

// LU factorization of a square matrix given in sparse form (sparse_lu.hpp), with Eigen vectors.
class LinearSolver {
 public:
  void analyze(const Eigen::SparseMatrix<double>& A);
  // False if the matrix is (numerically) singular.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  void solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const;
  void solve_transposed(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  int size() const { return n_; }
  int sign_determinant() const { return lu_.sign_determinant(); }
  // See SparseLU::adopt_pivots: `other` factorized a matrix of A's pattern.
  void adopt_pivots(const LinearSolver& other, const Eigen::SparseMatrix<double>& A) { lu_.adopt_pivots(other.lu_, A); }

 private:
  int n_ = 0;
  SparseLU lu_;
};

}  // namespace spacar
