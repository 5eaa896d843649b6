// Dynamic analysis (formulation.md §3): mass matrix, convective inertia and applied forces,
// constitutive stresses and the reduced equations of motion in the degrees of freedom.
#pragma once

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

class ExplicitChain;

// σ = S e + D ė for the deformations whose stresses are constitutive (released, dynamic,
// kinematic); the others are reactions and are set to 0 here.
void constitutive_stresses(const System& sys, Data& data);

// Element mass matrices and convective forces, rigid-body inertias, and the global h and f at
// the current x, ẋ (the element work vectors must hold x and v).
void compute_inertia_and_loads(const System& sys, Data& data);
// inertia_residual = M ẍ + h − f (after compute_inertia_and_loads).
void inertia_force(const System& sys, Data& data);
// out = M acc, element by element (point masses, element masses, rigid bodies; after
// compute_inertia_and_loads).
void inertia_times(const System& sys, const Data& data, const Eigen::VectorXd& acc, Eigen::VectorXd& out);
// The dense global mass matrix (full path).
void assemble_mass_matrix(const System& sys, Data& data);

// Residual of the reduced equations of motion at the current q̂̈ (formulation.md §7.2):
// R = DF_qᵀ [M ẍ + h − f] + DFe_qᵀ σ. Requires positions, DF and velocities.
void reduced_residual(const System& sys, Data& data, Eigen::VectorXd& R);
// The same residual without transfer functions (cost linear in the model size): accelerations
// and DF_qᵀ from solves with the velocity block (requires positions and solve_velocities_direct)
// or, given an open chain, block by block (requires positions and chain->solve_velocities).
void reduced_residual_direct(const System& sys, Data& data, Eigen::VectorXd& R, ExplicitChain* chain = nullptr);

// The deformations whose stresses follow from their constitutive law (σ = S e + D ė).
inline bool constitutive_class(DefClass c) {
  return c == DefClass::Released || c == DefClass::Dynamic || c == DefClass::Kinematic;
}

// The DOF accelerations q̈ into data: data.qdd and their columns of q̂̈ (qdd may be data.qdd).
void set_dof_accelerations(const System& sys, Data& data, const Eigen::VectorXd& qdd);
// Solve M̄ q̈ = rhs (3.1) and complete ẍ, ë. Requires positions, DF and velocities.
// Throws SingularMassError naming the degrees of freedom without inertia.
void solve_dynamics(const System& sys, Data& data);

// The same motion without transfer functions (the integration path): one sparse solve of the
// equations of motion of the free coordinates with the constraint rows,
//   [M_ff B_Cfᵀ; B_Cf 0] [ẍ_f; σ^C] = [−g_f; ë^C − c^C],
// which also yields the reaction stresses σ^C. Requires positions and solve_velocities_direct.
void solve_dynamics_direct(const System& sys, Data& data);
// The same state when the DOFs' accelerations q̈ are already known (the recursive path's, from
// the articulated-body algorithm), without the equations of motion: ẍ and ë from the
// second-order kinematics, and the stresses of the constraint rows from the equilibrium of the
// calculable coordinates, A_Vᵀ σ^V = −[M ẍ + h − f + Σ B_kᵀ σ_k]_c with the released and
// kinematic deformations' stresses known (as nodal_reactions); the DOF rows keep their
// constitutive stresses. The solution of solve_dynamics_direct when q̈ solves the equations of
// motion, at the cost of two solves with the velocity block instead of the factorization of
// the whole system. Requires positions and solve_velocities_direct; false (nothing solved)
// when the velocity block is not square.
bool solve_dynamics_known(const System& sys, Data& data, const Eigen::VectorXd& qdd);
// Nodal reactions (6.2) from the complete stresses (after solve_dynamics_direct).
void nodal_reactions(const System& sys, Data& data);

// Kinetic energy T = ½ ẋᵀ M ẋ (requires compute_inertia_and_loads) and potential energy of
// the constitutive springs and of gravity; for tests and energy balances.
double kinetic_energy(const System& sys, const Data& data);
double potential_energy(const System& sys, const Data& data);
// Its two parts: ½ eᵀ S e of the constitutive deformations, and the potential of gravity.
double strain_energy(const System& sys, const Data& data);
double gravity_potential(const System& sys, const Data& data);
// The power dissipated by the dampers (ėᵀ D ė) and the power of the external loads and drivers
// (FORCE, TORQUEL, Data::time_load, prescribed inputs through their reactions), at a solved state
// with complete stresses (after solve_dynamics_direct): d(T + V + U)/dt = external − dissipated.
struct EnergyRates {
  double dissipated = 0.0, external = 0.0;
};
EnergyRates energy_rates(const System& sys, const Data& data);

}  // namespace spacar
