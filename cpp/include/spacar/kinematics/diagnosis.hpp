// Diagnosis of what went wrong, kept out of the hot functions (kinematics.cpp, dynamics.cpp),
// which call it only once they have failed: which constraints are redundant and which
// coordinates undetermined, where the velocity block is nearly singular, and which degrees of
// freedom move no mass.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

// Diagnosis of the position constraint block A_P (or, velocity = true, of the velocity block A_V,
// whose rows hold the nonholonomic deformations instead of their kinematic coordinates) at the
// current positions (formulation.md §2.3, §5).
// Above this many constraints or calculable coordinates the diagnosis gives the counts only
// (rank = -1): the SVD and the selections are cubic in the size and would take minutes.
constexpr int kMaxDiagnosisSize = 1500;

struct ConstraintDiagnosis {
  int n_constraints = 0, n_calculable = 0, rank = 0;  // rank -1: not computed (too large)
  std::vector<int> redundant;     // deformations whose release removes the redundancy
  std::vector<int> undetermined;  // calculable coordinates left undetermined
  // Over-constrained: the coordinates the user prescribed (DYNX degrees of freedom, INPUTX
  // inputs) that the constraints determine; making one of them calculable again removes a
  // redundancy as releasing a deformation does (the usual cause: a DYNX added too many).
  std::vector<int> determined;
  // From the SVD: dependent combinations of rows and free motions, (index, weight).
  std::vector<std::vector<std::pair<int, double>>> redundant_groups, undetermined_groups;
  std::string text;               // readable report naming elements and nodes
};
// velocity: the velocity block (rows V) instead of the position block (rows P).
// release_dynamic: name the redundancy among the dynamic deformations (DYNE) where it can, keeping
// the fixed and input rows (SPACAR Light's automatic release turns such DYNE into RLSE); by
// default among the fixed deformations, keeping the prescribed rows.
ConstraintDiagnosis diagnose(const System& sys, Data& data, bool velocity = false, bool release_dynamic = false);
std::string diagnose_constraints(const System& sys, Data& data, bool velocity = false);
// If the velocity constraint block is nearly singular (a dead point): which constraints lose
// their independence and which coordinates move; "" otherwise.
std::string weakest_constraint(const System& sys, Data& data);


// SingularMassError naming the degrees of freedom with the largest components of the null
// vectors of the reduced mass matrix M̄ (those that move no mass).
[[noreturn]] void throw_singular_mass(const System& sys, const Data& data, const Eigen::MatrixXd& Mbar);
// The sparse equations of motion could not be factorized: name the degrees of freedom without
// inertia through the reduced equations (transfer functions, M̄), else SingularMassError.
[[noreturn]] void explain_singular_equations(const System& sys, Data& data);
// SingularMassError at once if the system has degrees of freedom, no mass anywhere and is too
// large for the dense diagnosis that names them (a run checks it before any work: a 20 000-beam
// chain without mass ran into its time limit in the assembly before, issue 38).
void refuse_large_massless(const System& sys, double t);

}  // namespace spacar
