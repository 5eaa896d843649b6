// Static equilibrium (issue 19, docs/statics.md): the configuration in which the reduced
// generalized forces of the degrees of freedom vanish at rest,
//   R(q, λ) = DF_qᵀ (−λ f) + DFe_qᵀ σ(e) = 0,
// the equations of motion (formulation.md §3.1) at zero velocity and acceleration, under the
// block's loads (FORCE, TORQUEL, GRAVITY) scaled by the load factor λ and with the inputs moved
// from their values at the block start to their values at the block end in proportion to λ.
// The path starts at the current state: R(q, λ) − (1 − λ) R(q_start, 0) = 0 is followed, the
// second term being zero from an unloaded, stress-free start (and the previous block's loads in
// generalized form when a block continues from an equilibrium).
// Full Newton with the exact tangent stiffness ∂R/∂q = K0 + G0 of the linearization (structural
// plus geometric, formulation.md §7.2; C0 = N0 = 0 at rest), solved through the sparse
// saddle-point system of the nodal coordinates (nodal.hpp, docs/formulation.md §10): no dense matrix
// of the model's size is formed. λ from 0 to 1 in equal load steps,
// a step halved when Newton fails there. No mass is needed. With arc_length the path is followed
// in (q, λ) instead (Riks' normal-plane arc-length method): past limit points, λ rising and
// falling, until λ = 1.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <chrono>
#include <memory>
#include <limits>
#include <string>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/errors.hpp"
#include "spacar/model/model.hpp"
#include "spacar/analyses/simulate.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

struct StaticOptions {
  int steps = 10;            // equal load steps from λ = 0 to 1; one result row each
  int max_iterations = 30;   // Newton iterations per (sub)step
  int max_cuts = 12;         // halvings of a load step before giving up
  double tolerance = 1e-10;  // residual relative to the largest generalized force balanced
  bool arc_length = false;   // follow the path in (q, λ) past limit points (see follow_arc_length)
  int max_steps = 200;       // arc-length steps before giving up (one result row each)
  double time_limit = 0.0;   // wall-clock seconds (0: no limit); beyond it TimeLimitError
};

struct StaticResults {
  std::vector<std::array<int, 2>> coord_label, def_label;  // (node, component), (element, deformation)
  std::vector<int> x_dyn, e_dyn;   // the degrees of freedom: coordinate and deformation indices
  Eigen::VectorXd load;            // load factor λ of each row (k / steps)
  RowMatrix x, e, sigma, reaction; // rows x nx / ne: sigma complete (reaction stresses included)
  std::vector<int> iterations;     // Newton iterations from the previous row (cut sub-steps included)
  double load_reached = 0.0;       // the last converged load factor (1 unless StaticError)
  long newton_iterations = 0;      // all Newton iterations, failed attempts included
  long step_cuts = 0;              // load steps halved because Newton failed
  long kinematic_iterations = 0;   // iterations of the position solves
  // First converged load factor at which the tangent stiffness is indefinite (an equilibrium
  // past a buckling or limit point: unstable), NaN if it never was.
  double indefinite_at = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> limit_points;  // arc length: load factors of the limit points passed
  double wall_time = 0.0;
  std::vector<std::string> warnings;
};

// The static state at load factor λ with the positions solved: the reduced generalized forces
// R = DF_qᵀ (−λ f + Σ Bᵀσ) (n_dof), from one transposed solve with the velocity block (no
// transfer functions). Leaves in data the rates at zero, data.f = λ f, the complete stresses σ
// (reaction stresses of the velocity rows from the equilibrium of the calculable coordinates)
// and the reactions on the fixed and input coordinates; full_load, if given: f at λ = 1. If K
// is not null, also the tangent stiffness ∂R/∂q = K0 + G0 (n_dof x n_dof), dense (the transfer
// functions formed): for tests and small models; the static path itself solves with the
// sparse tangent of the nodal coordinates (nodal.hpp). Returns the scale of R: the largest
// applied or elastic load on a coordinate (loads on lengths times the mean element length).
// chain: the kinematics of an open chain (its blocks' solves instead of the velocity block's).
double static_forces(const System& sys, Data& data, double lambda, Eigen::VectorXd& R, Eigen::MatrixXd* K = nullptr,
                     Eigen::VectorXd* full_load = nullptr, ExplicitChain* chain = nullptr);

// "DYNX node 3 component 2" / "DYNE element 2 (PLBEAM) deformation 3" of degree of freedom j.
std::string dof_name(const System& sys, int j);
// The characteristic size of each DOF: the mean element length for lengths, 1 for angles.
Eigen::VectorXd dof_scale(const System& sys);
// "the direction of ..." the DOFs that make up the directions V (columns) of q: components ≥ 10%
// of the largest, the largest first, at most four named.
std::string dof_directions(const System& sys, const Eigen::MatrixXd& V);

// The static analysis of the model's current block: assemble at λ = 0, follow the equilibrium to
// λ = 1 and store it in the model (at rest, at the block's start time). On failure StaticError
// with `res` holding the rows converged before it; the model is then not changed.
void solve_static(Model& model, StaticResults& res, const StaticOptions& options = {});

class ReducedSystem;

// The static analysis of one model set up once and solved many times (spacar.StaticSolver): the
// model prepared and compiled, its open chain recognized and the pattern and ordering of the
// tangent's saddle-point system made when the solver is made, a third of a single solve of a few
// hundred beams. Each solve starts again from the state the model had then, with the model's
// loads or others on its nodal coordinates (a load case). solve_static is one solve of a solver.
class StaticSolver {
 public:
  // The model (prepared here: the first END) must outlive the solver.
  explicit StaticSolver(Model& model) : StaticSolver(model, nullptr) {}
  ~StaticSolver();
  StaticSolver(const StaticSolver&) = delete;
  StaticSolver& operator=(const StaticSolver&) = delete;

  // solve_static's path of equilibria from the model's state when the solver was made, within
  // opt.time_limit. `force`: the FORCE loads on the nodal coordinates (nx, in the order of
  // system().coord_label) in place of the model's, applied with the load factor as they are;
  // nullptr: the model's.
  void solve(StaticResults& res, const StaticOptions& opt, const Eigen::VectorXd* force = nullptr);
  // The model's state set to the end of the last solve, as spacar.static leaves it.
  void store_state() { sim_.store_state(); }
  const System& system() const { return sim_.system(); }

 private:
  friend void solve_static(Model& model, StaticResults& res, const StaticOptions& options);
  using Clock = std::chrono::steady_clock;
  // `first`: the options of the first solve, whose memory is checked before the set-up.
  StaticSolver(Model& model, const StaticOptions* first);
  void run(StaticResults& res, const StaticOptions& opt, const Eigen::VectorXd* force, Clock::time_point start);

  Simulation sim_;
  std::unique_ptr<ExplicitChain> chain_;    // nullptr: not an open chain
  std::unique_ptr<ReducedSystem> reduced_;  // the tangent's saddle-point system
  Eigen::VectorXd x0_;                      // the model's positions: each solve's assembly starts there
  bool fresh_ = true;                       // no solve yet: the work arrays as constructed
};

// The rows T (m x nx) of the displacements of the nodes: a position node's coordinates, a BETA
// node's angle, a LAMBDA node's small rotation vector in global axes, δθ = 2 E(λ) δλ.
// InputError for a node without coordinates used by an element.
Eigen::MatrixXd displacement_rows(const System& sys, const Data& data, const std::vector<int>& nodes);
// Put data (assembled) at a row of static results: the positions x, the independent
// coordinates from x and e, the positions re-solved there; InputError naming `where` if a size
// is wrong.
void put_at_static_row(const System& sys, Data& data, const Eigen::VectorXd& x, const Eigen::VectorXd& e,
                       const char* where);
// The static compliance C = T DF_q K⁻¹ DF_qᵀ Tᵀ at the nodes (spacar.compliance), T the rows of
// their displacements (m x nx: a position node's coordinates, a BETA node's angle, a LAMBDA
// node's small rotation vector in global axes, δθ = 2 E(λ) δλ), K = K0 + G0 the tangent
// stiffness of the static solve at load_factor times the block's loads: one solve of the sparse
// saddle-point system per row of T (no dense matrix of the model's size). At the model's
// current state or, given both x and e (a row of static results), at that row: the model is
// assembled as a simulation does and put there. InputError if only one of x, e is given or a
// size is wrong; StaticError naming the direction if K is singular.
Eigen::MatrixXd static_compliance(Model& model, const std::vector<int>& nodes, double load_factor = 1.0,
                                  const Eigen::VectorXd* x = nullptr, const Eigen::VectorXd* e = nullptr);

}  // namespace spacar
