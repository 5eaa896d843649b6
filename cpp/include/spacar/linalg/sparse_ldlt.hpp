// Sparse LDLᵀ of a symmetric matrix in a fixed symmetric order, without pivoting (the up-looking
// algorithm of Davis' LDL: row k of L from one sparse triangular solve along the elimination
// tree). It serves the saddle-point systems of the nodal analyses (nodal.hpp), whose order puts
// every constraint row after the coordinates it constrains, so that no pivot is structurally
// zero; the factorization gives the inertia (the count of negative pivots, by Sylvester's law
// of inertia) that a pivoting LU cannot.
#pragma once

#include <Eigen/Sparse>
#include <vector>

namespace spacar {

class SparseLDLT {
 public:
  // Prepare for symmetric matrices of A's pattern (both triangles stored), eliminated in `order`
  // (step → row/column of A). The symbolic factorization: elimination tree and column counts.
  void analyze(const Eigen::SparseMatrix<double>& A, const std::vector<int>& order);
  // Factorize A (the pattern of analyze). A pivot of magnitude at most `tiny` is replaced by
  // ±tiny (its sign kept, + for zero) and counted in perturbed(): the matrix is singular to
  // working precision there, and a solve then returns the direction of that singularity
  // amplified (inverse iteration). False if A or the factors hold non-finite values.
  bool factorize(const Eigen::SparseMatrix<double>& A, double tiny);
  // x = A⁻¹ b (x may alias b).
  void solve(const double* b, double* x) const;

  int size() const { return n_; }
  int negative() const { return negative_; }    // negative pivots: negative eigenvalues of A
  int perturbed() const { return perturbed_; }  // pivots replaced by ±tiny
  int sign_determinant() const { return negative_ % 2 ? -1 : 1; }
  int factor_nonzeros() const { return n_ ? Lp_[n_] : 0; }
  const std::vector<double>& pivots() const { return D_; }  // by step

 private:
  int n_ = 0;
  std::vector<int> order_;           // step → index of A
  // The permuted upper triangle C = (P A Pᵀ) by columns: rows as steps, values as positions in
  // A's value array.
  std::vector<int> Cp_, Ci_, Cpos_;
  std::vector<int> parent_, Lp_, Li_;
  std::vector<double> Lx_, D_;
  int negative_ = 0, perturbed_ = 0;
  // Work space of size n, never reallocated after analyze.
  mutable std::vector<double> y_;
  std::vector<int> pattern_, flag_, count_;
};

}  // namespace spacar
