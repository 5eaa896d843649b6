// Reaction forces and element stresses (FORCEMODE; formulation.md §6). With the motion known
// (q̈ solved), every calculable coordinate is in equilibrium with the complete stress vector:
//   A_Vᵀ σ^V = −[g + B_Wᵀ σ^W]_c,   g = M ẍ + h − f,                               (6.1)
//   r = [g + Bᵀ σ]_{o,p}                                                           (6.2)
// σ^W (released, kinematic, dynamic) are constitutive; σ of fixed, input, LINE and
// nonholonomic deformations are reactions; r are the loads of the supports and drivers on the
// nodes (fixed and input coordinates).
#pragma once

#include "spacar/data.hpp"
#include "spacar/system.hpp"

namespace spacar {

// Requires a complete evaluation (positions, DF with the velocity factorization, velocities,
// accelerations, M, h, f and constitutive stresses). Fills data.sigma (complete) and
// data.reaction, and for the consistency checks of §6 data.residual_load (g + DDᵀσ on every
// coordinate) and data.sigma_equilibrium (σ of every velocity row from (6.1)).
void solve_reactions(const System& sys, Data& data);

}  // namespace spacar
