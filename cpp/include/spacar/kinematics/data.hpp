// Data: every array that changes during an analysis, allocated once per System and reused at
// every step (Model/Data split as in Pinocchio and MuJoCo). Shapes are given as rows x cols.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "spacar/linalg/sparse.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

// Row-major results, one row per state (the output arrays, Python's layout).
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// States given one per row (q, q̇, ... of a batch), read in place: from NumPy without a copy when
// they are float rows of unit stride.
using StateRows = Eigen::Ref<const RowMatrix>;

struct ElementWork {
  Eigen::VectorXd x, v, a;      // local coordinates, velocities, accelerations (nc)
  Eigen::MatrixXd B;            // ∂e/∂x (nd x nc)
  Eigen::VectorXd c;            // convective term vᵀHv (nd)
  Eigen::MatrixXd M;            // element mass (nc x nc)
  Eigen::VectorXd h, f;         // convective inertia force, gravity load (nc)
};

struct Data {
  explicit Data(const System& sys);
  // The state back to the constructor's (zeros, the integrated deformations at their targets,
  // no angle branches, no reusable Jacobian, no load case, the LUs' pivots forgotten), the sizes
  // and the patterns built on first use kept: a prepared analysis (StaticSolver) starts each
  // solve from here. The dense arrays of ensure_dense are not reset (no static solve reads them).
  // keep_pivots: the LUs replay their last pivot sequences (each replayed pivot checked: a poor
  // one makes that factorization choose again), for the next block of a run (Simulation::renew),
  // whose digits then may differ from a fresh analysis's in the last places.
  void reset_state(const System& sys, bool keep_pivots = false);
  // Allocate the dense matrices of the full path (transfer functions, reduced mass matrix).
  void ensure_dense(const System& sys);
  bool dense_ready = false;
  // Build the sparse equations of motion (the system of solve_dynamics_direct, its pattern and
  // ordering) on first use: the recursive path's runs never solve them.
  void ensure_equations_of_motion(const System& sys);
  bool equations_ready = false;
  // Build the constraint blocks AP, AV (pattern and ordering) on first use (assemble_block):
  // the open chains' kinematics and statics never assemble them.
  void ensure_constraint_blocks(const System& sys);
  bool constraint_blocks_ready = false;
  // Bytes an analysis of `sys` allocates on the sparse path (vectors, element work arrays, the
  // constraint blocks and the equations of motion with room for the fill of their factors), and
  // in addition for the dense matrices of ensure_dense (transfer functions, mass matrices, the
  // linearization's constitutive matrices). Checked against the memory limit before allocating.
  static double estimate_bytes(const System& sys);
  static double estimate_dense_bytes(const System& sys);

 private:
  void build_constraint_blocks(const System& sys);
  void analyze_constraint_blocks(const System& sys);  // the LUs of AP and AV, when square
  // The places of the free coordinates and constraint rows in the equations of motion.
  void number_equations_of_motion(const System& sys);

 public:
  double t = 0.0;
  Eigen::VectorXd x, xd, xdd;   // nodal coordinates and their derivatives (nx)
  Eigen::VectorXd e, ed, edd;   // deformations and their derivatives (ne)
  Eigen::VectorXd sigma;        // generalized stresses (ne)
  Eigen::VectorXd qhat, qhat_d, qhat_dd;  // independent coordinates (n_qhat)
  std::vector<ElementWork> work;

  // Kinematics.
  Eigen::VectorXd target;       // targets of the position rows P (|P|)
  Eigen::VectorXd e_integrated; // current values of the integrated deformations y (ne; others unused)
  Eigen::VectorXd angle_ref;    // last value of each angle-type deformation (unwrapping), NaN: none
  Eigen::VectorXd residual;     // D^P(x) − target (|P|)
  BlockMatrix AP, AV;           // constraint blocks ∂D^P/∂x^c and ∂D^V/∂x^c (sparse, fixed pattern; see ensure_constraint_blocks)
  std::vector<int> AP_block, AV_block;  // block id of each element in AP / AV
  LinearSolver luP, luV;        // their factorizations
  bool jacobian_reusable = false;  // luV holds the position block at the last solved positions
  Eigen::VectorXd rhs_V, sol_V; // right-hand side and solution of a velocity-level solve (|V|, n_c)
  // Dense transfer functions, allocated on first use (linearization, Simulation::evaluate).
  Eigen::MatrixXd rhs_DF;       // right-hand sides of the transfer functions (|V| x n_qhat)
  Eigen::MatrixXd DF;           // first-order transfer function ∂x/∂q̂ (nx x n_qhat)
  Eigen::MatrixXd DFe;          // ∂e/∂q̂ (ne x n_qhat)
  Eigen::VectorXd conv;         // convective terms c of all deformations (ne)
  Eigen::VectorXd acc0;         // ẍ for q̂̈ = 0: the second-order transfer term a (nx)
  Eigen::VectorXd step;         // Newton step / scratch (n_c)
  int newton_iterations = 0;    // of the last position solve
  long total_newton_iterations = 0;

  // Dynamics in the coordinates (the integration path): the equations of motion of the free
  // coordinates f = (x^c, x^d) with the constraint rows C (fixed, input, LINE, nonholonomic
  // deformations) as one sparse system  [M_ff B_Cfᵀ; B_Cf 0] [ẍ_f; σ^C] = [−g_f; ë^C − c^C].
  std::vector<int> free_index;  // coordinate → position among the free coordinates, −1
  std::vector<int> c_row;       // deformation → constraint row of C, −1
  int n_free = 0, n_c_rows = 0;
  BlockMatrix KKT;              // built by ensure_equations_of_motion, at the first solve
  std::vector<int> KKT_mass, KKT_B, KKT_Bt;  // block ids per element (−1: none)
  std::vector<int> KKT_point, KKT_body;      // block ids of point masses and rigid bodies
  LinearSolver luK;
  Eigen::VectorXd kkt_rhs, kkt_sol;
  Eigen::VectorXd acc_known;    // accelerations known before the solve: inputs (nx)
  std::vector<Eigen::Matrix4d> body_M;  // rigid-body inertia of each LAMBDA body (Euler parameters)
  std::vector<Eigen::Vector4d> body_h;

  // Dense dynamics of the reduced equations (full path, allocated on first use).
  Eigen::MatrixXd M;            // global mass matrix (nx x nx)
  Eigen::VectorXd h, f;         // convective inertia and applied forces (nx)
  Eigen::VectorXd time_load;    // time-dependent loads at t added to FORCE (nx; empty: none)
  Eigen::VectorXd constant_load;  // FORCE in place of the system's (nx; empty: sys.force): a StaticSolver's load case
  Eigen::MatrixXd DFq;          // DF restricted to the DOF columns (nx x n_dof)
  Eigen::MatrixXd Mbar;         // reduced mass matrix (n_dof x n_dof)
  Eigen::VectorXd rhs;          // reduced force (n_dof)
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd qdd;          // DOF accelerations (n_dof)
  // M ẍ + h − f (nx): the inertia and applied loads the stresses must balance (not gravity g).
  Eigen::VectorXd inertia_residual;
  Eigen::VectorXd reaction;     // loads of supports and drivers on fixed and input coordinates (nx)
  // Consistency of the reactions with the motion (formulation.md §6): M ẍ + h − f + DDᵀσ on every
  // coordinate (the reactions on fixed and input rows, ≈ 0 on the others) and σ of every
  // velocity row from (6.1), degree-of-freedom rows included (0 on the other rows).
  Eigen::VectorXd residual_load;      // (nx)
  Eigen::VectorXd qhat_load;          // DFᵀ of a load (n_qhat)
  Eigen::VectorXd sigma_equilibrium;  // (ne)
};

}  // namespace spacar
