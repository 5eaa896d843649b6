// The analyses of flexible structures in the nodal coordinates (docs/formulation.md §10): the
// stiffness, geometric stiffness, mass and damping assembled element by element as sparse
// matrices over the free coordinates x_f = (x^c, x^d), and the constraint rows A, the velocity
// rows whose deformation is not a degree of freedom (rigid, input, LINE), restricted to x_f.
// The reduced matrices of the degrees of freedom are Zᵀ H Z with Z = DF_q, the transfer function
// of the DOFs (formulation.md §7.2), which is dense; they are never formed here. Instead a
// reduced system (Zᵀ H Z) δq = Zᵀ r is solved through the sparse saddle-point system
//   [H + AᵀWA   Aᵀ] [δx_f]   [r]
//   [A          0 ] [ μ  ] = [0],   δx_f = Z δq,
// whose cost is linear in the size of a chain or a mesh. AᵀWA (W > 0 diagonal) changes
// neither the solution (A δx_f = 0) nor the inertia: the matrix is congruent to the one
// without it, so its negative eigenvalues are those of Zᵀ H Z plus one per constraint row.
// It gives every coordinate that only a constraint holds a pivot of its own, so that the
// symmetric factorization needs no pivoting when each constraint row is eliminated after its
// coordinates. The system is solved in scaled units (lengths by the mean element length, so
// that H holds energies; each constraint row scaled to the size of H), where all pivots are
// comparable and a tiny one means a singular reduced matrix.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <array>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/linalg/sparse.hpp"
#include "spacar/linalg/sparse_ldlt.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

// The numbering of the nodal analyses.
struct NodalLayout {
  explicit NodalLayout(const System& sys);
  int n_free = 0, n_rows = 0;
  std::vector<int> free;         // free index → coordinate (calculable, then DOF coordinates)
  std::vector<int> free_of;      // coordinate → free index, −1
  std::vector<int> rows;         // constraint row → deformation
  std::vector<int> row_of;       // deformation → constraint row, −1
  // The size of each free coordinate and constraint row (the mean element length for lengths,
  // 1 for angles): the saddle-point system is solved in these units, where all its entries are
  // energies, so that its pivots compare.
  Eigen::VectorXd scale;         // n_free + n_rows
};

// What a nodal matrix holds (bit mask).
enum NodalPart : unsigned {
  kStiffness = 1,    // Bᵀ S B over the constitutive deformations (ESTIFF)
  kGeometric = 2,    // Σ σ_k ∂²e_k/∂x² − ∂f/∂x: the stresses' geometric stiffness and the loads'
  kMass = 4,         // element, point and rigid-body masses
  kDamping = 8,      // Bᵀ D B over the constitutive deformations (EDAMPP)
};

// Coefficients of H = k·stiffness + g·geometric + m·mass + d·damping. The load stiffness
// (position-dependent gravity of element masses, body-fixed torques) enters the geometric part
// scaled by load_factor (the static path's λ), the stresses' part by g alone.
struct NodalCoefficients {
  double stiffness = 1.0, geometric = 1.0, mass = 0.0, damping = 0.0;
  double load_factor = 1.0;
};

// H = k·stiffness + g·geometric + m·mass + d·damping (NodalCoefficients) in the nodal
// coordinates as a sparse matrix over all coordinates (nx x nx; the rows and columns of fixed
// and input coordinates included), at the current state (element work arrays evaluated:
// positions, B; masses from compute_inertia_and_loads) for the stresses sigma.
Eigen::SparseMatrix<double> nodal_matrix(const System& sys, Data& data, const Eigen::VectorXd& sigma,
                                         const NodalCoefficients& c);
// One part alone (a NodalPart), the load stiffness at load factor 1.
Eigen::SparseMatrix<double> nodal_part(const System& sys, Data& data, const Eigen::VectorXd& sigma, unsigned part);
// The quadratic forms vᵀ K v, vᵀ G v, vᵀ M v, vᵀ D v (the parts of NodalPart, the load
// stiffness at load factor 1) for a displacement v of the coordinates (nx), element by element
// from the deformations' increments B v and second derivatives vᵀ ∂²e/∂x² v, not from the
// assembled matrices: for the smooth modes of a fine mesh the products K v cancel to a small
// fraction of their terms, and vᵀ K v from them would carry the rounding errors of the large
// entries (relative errors of ε times the matrix's condition); these carry ε times the number
// of elements along a chain at most. The Rayleigh quotients of the sparse eigen-analyses.
Eigen::Vector4d nodal_energies(const System& sys, Data& data, const Eigen::VectorXd& sigma, const Eigen::VectorXd& v);
// The constraint rows A (layout.rows x nx) and the map E from the coordinates to the reduced
// coordinates q: δq = E δx (unit rows for DOF coordinates, B rows for DOF deformations).
Eigen::SparseMatrix<double> nodal_constraints(const System& sys, const Data& data, const NodalLayout& layout);
Eigen::SparseMatrix<double> nodal_dof_map(const System& sys, const Data& data);
// B = ∂e/∂x of all deformations (ne x nx), and the constitutive matrix (ne x ne: the rows of the
// constitutive deformations, σ = S e + D ė; `damping`: D instead of S).
Eigen::SparseMatrix<double> nodal_deformation_jacobian(const System& sys, const Data& data);
Eigen::SparseMatrix<double> nodal_constitutive(const System& sys, bool damping);

// The saddle-point system above with its factorization: LDLᵀ (with the inertia) when H is
// symmetric, the pivoting LU when body-fixed torques make it unsymmetric.
class SaddlePoint {
 public:
  SaddlePoint(const System& sys, const NodalLayout& layout);

  // Assemble H + AᵀWA and A at the current state for the stresses sigma; factorize. False if
  // the values are not finite or (LU) the matrix is singular. same_state: the state and the
  // stresses of the last call, other coefficients only (a new step of an implicit integrator):
  // the elements' matrices per unit coefficient kept from it are combined again, not evaluated.
  bool factorize(const System& sys, Data& data, const Eigen::VectorXd& sigma, const NodalCoefficients& c,
                 bool same_state = false);
  // δx (nx; zero on fixed and input coordinates) for a load r on the coordinates (nx; its
  // entries on fixed and input coordinates ignored): δx = Z (Zᵀ H Z)⁻¹ Zᵀ r; `refine`: with one
  // step of iterative refinement (the factorization chose its pivots for no accuracy).
  void solve(const Eigen::VectorXd& r, Eigen::VectorXd& dx, bool refine = true);
  // The same over the free coordinates (n_free), for the eigen-analyses.
  void solve_free(const double* r, double* dx, bool refine = true);

  bool symmetric() const { return symmetric_; }
  // The LU's pivot sequence forgotten (it is replayed from one factorization to the next): the
  // next factorization chooses its pivots, as the first did.
  void forget_pivots() {
    if (!symmetric_) lu_.analyze(kkt_.matrix());
  }
  // Of the reduced matrix Zᵀ H Z: singular to working precision (a tiny pivot), the sign of
  // its determinant, and its negative eigenvalues (−1 when unknown: the unsymmetric case).
  bool singular() const { return singular_; }
  int sign_determinant() const { return sign_; }
  int negative_eigenvalues() const { return negative_; }
  // δx (nx) of a direction in which Zᵀ H Z is singular (after a factorization that found it
  // singular, symmetric case; empty otherwise): inverse iteration on the perturbed factors.
  Eigen::VectorXd null_direction();
  // A direction of the lowest eigenvalue of Zᵀ H Z in the metric of the scaled coordinates
  // (inverse iteration with shift); δx, with its Rayleigh quotient in `value`.
  Eigen::VectorXd lowest_direction(int iterations, double& value);

  const NodalLayout& layout() const { return layout_; }
  const Eigen::SparseMatrix<double>& matrix() const { return kkt_.matrix(); }
  // Element i's part of the last H without its constitutive terms (the geometric stiffness, the
  // loads' stiffness, the mass, with their coefficients; local, n x n, unscaled).
  Eigen::Map<const Eigen::MatrixXd> element_rest(size_t i, int n) const {
    return Eigen::Map<const Eigen::MatrixXd>(rest_.data() + rest_start_[i], n, n);
  }

 private:
  void assemble(const System& sys, Data& data, const Eigen::VectorXd& sigma, const NodalCoefficients& c,
                bool same_state);
  // The elements' part `part` per unit coefficient at the current state into parts_[part].
  void hold_part(const System& sys, const Data& data, const Eigen::VectorXd& sigma, int part, double load_factor);
  void solve_scaled(Eigen::VectorXd& rhs, bool refine);  // in place

  const NodalLayout& layout_;
  int n_ = 0;
  bool symmetric_ = true;
  BlockMatrix kkt_;
  std::vector<int> element_block_, row_block_, column_block_, point_block_, body_block_, torque_block_;
  std::vector<int> diagonal_;    // value position of each diagonal entry (free part)
  // The scale of each element's coordinates (layout.scale; 1 where not free), element i's from
  // element_scale_[element_scale_start_[i]].
  std::vector<double> element_scale_;
  std::vector<int> element_scale_start_;
  SparseLDLT ldlt_;
  LinearSolver lu_;
  bool singular_ = false;
  int sign_ = 1, negative_ = -1;
  Eigen::VectorXd rhs_, sol_, res_;
  Eigen::MatrixXd local_, rows_;  // an element's block of H and its rows of A (work space)
  // element_rest of every element in one array (one allocation, not one per element), element
  // i's n x n values (column-major) from rest_start_[i].
  std::vector<double> rest_;
  std::vector<int> rest_start_;
  // Every element's matrices per unit coefficient at the state of the last assembly, laid out as
  // rest_: the geometric part (stresses and loads, at held_load_factor_), the mass, the
  // stiffness and the damping; held_[p]: part p is of that state.
  enum Part { kGeometric, kMass, kStiffness, kDamping, kParts };
  std::array<std::vector<double>, kParts> parts_;
  std::array<bool, kParts> held_{};
  double held_load_factor_ = 0.0;
};

// The reduced system of the degrees of freedom q of sys (x^d, e^d),
//   (Zᵀ H Z) q = r,   Z = DF_q,
// solved through the saddle-point system with iterative refinement in q. The saddle-point
// solution carries the rounding of the assembled matrices of a fine mesh (ε times their
// condition: 2e-9 on a cantilever of 100 beams, 1e-5 on 3200); the residual r − Zᵀ H Z q
// computed from the deformations does not (the DOF deformations exactly, the constitutive
// stresses from them, the rest of H element by element, Zᵀ by one transposed solve with the
// velocity block), and two refinements bring q to round-off. Needs data at a solved state with
// the velocity block factorized there (after static_forces or solve_velocities_direct).
class ReducedSystem {
 public:
  ReducedSystem(const System& sys, Data& data);

  // H for the stresses sigma and the coefficients at the current state, factorized; false if
  // its values are not finite (see SaddlePoint::factorize, also for same_state).
  bool factorize(const Eigen::VectorXd& sigma, const NodalCoefficients& c, bool same_state = false);
  // q = (Zᵀ H Z)⁻¹ r and dx = Z q (nx), with at most `refinements` steps of refinement (0: the
  // saddle-point solution as it is, enough for a Newton step, whose residual is exact).
  void solve(const Eigen::VectorXd& r, Eigen::VectorXd& q, Eigen::VectorXd& dx, int refinements = kRefinements);
  // Zᵀ H Z q from the deformations (the refinement's product); dx, if given: Z q.
  Eigen::VectorXd product(const Eigen::VectorXd& q, Eigen::VectorXd* dx = nullptr);
  // q = (Zᵀ H Z)⁻¹ M̄ v, M̄ = Zᵀ M Z the reduced mass (element, point and body masses at the
  // state), and dx = Z q, without refinement.
  void solve_mass(const Eigen::VectorXd& v, Eigen::VectorXd& q, Eigen::VectorXd& dx);
  Eigen::VectorXd reduce(const Eigen::VectorXd& b);        // Zᵀ b for a load b on the coordinates
  Eigen::VectorXd load(const Eigen::VectorXd& v) const;    // a load b with Zᵀ b = v (nx)
  Eigen::VectorXd dofs(const Eigen::VectorXd& dx) const;   // E dx: the DOFs of a motion
  Eigen::VectorXd motion(const Eigen::VectorXd& q);        // Z q (nx)

  SaddlePoint& saddle() { return saddle_; }
  void forget_pivots() { saddle_.forget_pivots(); }
  const NodalLayout& layout() const { return layout_; }
  static constexpr int kRefinements = 3;

 private:
  const System& sys_;
  Data& data_;
  NodalLayout layout_;
  SaddlePoint saddle_;
  NodalCoefficients c_;
  std::vector<int> dof_of_def_;  // deformation → its DOF index, −1
};

}  // namespace spacar
