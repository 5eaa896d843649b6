// Data: every array that changes during an analysis, allocated once per System and reused at
// every step (Model/Data split as in Pinocchio and MuJoCo). Shapes are given as rows x cols.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "spacar/system.hpp"

namespace spacar {

struct ElementWork {
  Eigen::VectorXd x, v, a;      // local coordinates, velocities, accelerations (nc)
  Eigen::MatrixXd B;            // ∂e/∂x (nd x nc)
  Eigen::VectorXd c;            // convective term vᵀHv (nd)
  Eigen::MatrixXd M;            // element mass (nc x nc)
  Eigen::VectorXd h, f;         // convective inertia force, gravity load (nc)
};

struct Data {
  explicit Data(const System& sys);
  // Bytes the analysis of `sys` allocates (these arrays, the factorizations and the temporaries
  // of the transfer functions and the linearization): checked against the memory limit before
  // anything is allocated, since the matrices are dense in the number of coordinates.
  static double estimate_bytes(const System& sys);

  double t = 0.0;
  Eigen::VectorXd x, xd, xdd;   // nodal coordinates and their derivatives (nx)
  Eigen::VectorXd e, ed, edd;   // deformations and their derivatives (ne)
  Eigen::VectorXd sigma;        // generalized stresses (ne)
  Eigen::VectorXd qhat, qhat_d, qhat_dd;  // independent coordinates (n_qhat)
  std::vector<ElementWork> work;

  // Kinematics.
  Eigen::VectorXd target;       // targets of the position rows P (|P|)
  Eigen::VectorXd angle_ref;    // last value of each angle-type deformation (unwrapping), NaN: none
  Eigen::VectorXd residual;     // D^P(x) − target (|P|)
  Eigen::MatrixXd A;            // constraint block ∂D^P/∂x^c (|P| x n_c), later ∂D^V/∂x^c
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  Eigen::MatrixXd rhs_DF;       // right-hand sides of the transfer functions (|V| x n_qhat)
  Eigen::MatrixXd DF;           // first-order transfer function ∂x/∂q̂ (nx x n_qhat)
  Eigen::MatrixXd DFe;          // ∂e/∂q̂ (ne x n_qhat)
  Eigen::VectorXd conv;         // convective terms c of all deformations (ne)
  Eigen::VectorXd acc0;         // ẍ for q̂̈ = 0: the second-order transfer term a (nx)
  Eigen::VectorXd step;         // Newton step / scratch (n_c)
  int newton_iterations = 0;    // of the last position solve
  long total_newton_iterations = 0;

  // Dynamics.
  Eigen::MatrixXd M;            // global mass matrix (nx x nx)
  Eigen::VectorXd h, f;         // convective inertia and applied forces (nx)
  Eigen::MatrixXd DFq;          // DF restricted to the DOF columns (nx x n_dof)
  Eigen::MatrixXd Mbar;         // reduced mass matrix (n_dof x n_dof)
  Eigen::VectorXd rhs;          // reduced force (n_dof)
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd qdd;          // DOF accelerations (n_dof)
  Eigen::VectorXd g;            // M ẍ + h − f (nx)
  Eigen::VectorXd reaction;     // loads of supports and drivers on fixed and input coordinates (nx)
};

}  // namespace spacar
