// Kinematic analysis (formulation.md §2): positions by Newton iteration on the calculable
// coordinates, first-order transfer functions DF, velocities, and the second-order
// (convective) terms that give accelerations.
#pragma once

#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

// Prescribed inputs at time t: p, ṗ, p̈ into x^p / targets of e^p and the input part of q̂.
void set_inputs(const System& sys, Data& data, double t);
// Input i (ordered as input_cols) at position p, rate pd, acceleration pdd: its column of q̂ and,
// for an input coordinate, x.
void set_input(const System& sys, Data& data, int i, double p, double pd, double pdd);
// Degrees of freedom q and their rates: x^d into x, e^d into the targets, q̂ parts.
void set_dofs(const System& sys, Data& data, const double* q, const double* qd);

// Targets of the position rows (data.target): fixed/LINE/kinematic values from the system,
// inputs and DOFs from q̂.
void set_targets(const System& sys, Data& data);

// e and the element first derivatives at data.x.
void evaluate_elements(const System& sys, Data& data);
// The same for element i alone (its angles unwrapped as evaluate_elements does; the targets set).
void evaluate_element(const System& sys, Data& data, int i);
// KinematicsError unless the fixed deformations without calculable coordinates (auto_released)
// are at their targets within tol.
void check_auto_released(const System& sys, const Data& data, double tol);

// Newton iteration on x^c until max|D^P(x) − target| ≤ tol, then one polish iteration; leaves e
// and B evaluated at the solution. assembly: allow max(max_iter, 50) iterations with
// backtracking (initial assembly of a roughly given geometry). exact_start: data.x already
// solves the constraints up to round-off (the recursive path's positions, not a prediction): no
// iteration at all when the residual is within tol. Throws KinematicsError.
void solve_positions(const System& sys, Data& data, int max_iter, double tol, bool assembly,
                     bool exact_start = false);
// The tolerance of the position solves of a simulation: EPSKIN, tightened to 1e-4 of the smaller
// of EPSINT and EPSIND (the step control's scale of a small coordinate is 1e-3 EPS: a looser
// residual is noise in the right-hand side that drives the step size and makes the implicit
// methods refactorize; benchmarks/error_control.py, the spin-up case), not below round-off.
double simulation_kinematic_tolerance(const System& sys);

// DF (∂x/∂q̂) and DFe (∂e/∂q̂) at the current positions; factorizes the velocity block.
void solve_transfer(const System& sys, Data& data);

// ẋ = DF q̂̇, ė = DFe q̂̇; convective terms c and acc0 = ẍ at q̂̈ = 0 (the D2F term).
void solve_velocities(const System& sys, Data& data);

// Velocities without transfer functions (the integration path): ẋ^c from one solve with the
// velocity block, ė = B ẋ, and the convective terms c.
void solve_velocities_direct(const System& sys, Data& data);

// The state at rest as solve_velocities_direct leaves it for zero rates (ẋ, ė and the convective
// terms zero) and, if `factorize`, the velocity block factorized at the current positions: the
// static analyses.
void rest_velocities(const System& sys, Data& data, bool factorize = true);

// ė = B ẋ and the convective terms c, element by element, for the current ẋ.
void deformation_rates(const System& sys, Data& data);

// ẍ = DF q̂̈ + acc0 and ë = B ẍ + c, for the current q̂̈.
void solve_accelerations(const System& sys, Data& data);
// ë = B ẍ + c, element by element, for the current ẍ (B and c at the current state).
void deformation_accelerations(const System& sys, Data& data);

// The same without transfer functions: ẍ^c from one solve with the velocity block (after
// solve_velocities_direct), ë = B ẍ + c.
void solve_accelerations_direct(const System& sys, Data& data);

// out = DFᵀ w (one entry per column of q̂) without forming DF: one solve with the transposed
// velocity block (after solve_velocities_direct). Uses the rhs_V/sol_V work vectors and leaves
// in sol_V the multipliers μ of A_Vᵀ μ = w^c (one per velocity row).
void transfer_transposed(const System& sys, Data& data, const Eigen::VectorXd& w, Eigen::VectorXd& out);
// dx = DF v (nx) for rates v of q̂ without forming DF: one solve with the velocity block (after
// solve_velocities_direct).
void transfer_times(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx);

// Assemble the constraint block A (AP or AV, `block`: its element block ids) at the current
// element derivatives.
void assemble_block(const System& sys, Data& data, BlockMatrix& A, const std::vector<int>& block);

// Check that the constraint block is square; throws KinematicsError with the diagnosis.
void check_constraint_counts(const System& sys, Data& data);

}  // namespace spacar
