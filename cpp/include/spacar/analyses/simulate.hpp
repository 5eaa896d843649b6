// One analysis block (what SPACAR does at an END): assemble the mechanism, then integrate the
// reduced equations of motion over the TIMESTEP interval in C++ with error control, or, without
// degrees of freedom, run the kinematic analysis at every output time. Results are recorded at
// the output times; the state reached is stored back into the model (for the dump and the
// next block).
#pragma once

#include <Eigen/Dense>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/integrators/integrator.hpp"
#include "spacar/analyses/linearize.hpp"
#include "spacar/analyses/nodal.hpp"
#include "spacar/analyses/rhs_path.hpp"
#include "spacar/model/model.hpp"
#include "spacar/model/system.hpp"
#include "spacar/model/table.hpp"

namespace spacar {

struct RunOptions {
  // AUTO: DOP853 until it detects stiffness, RADAU5 until the stiffness goes (integrate_block).
  Method method = Method::DOP853;
  // GENERALIZED_ALPHA: the spectral radius at infinite frequency, in [0, 1] (1: no numerical
  // damping; generalized_alpha.hpp).
  double rho_inf = 0.9;
  // GENERALIZED_ALPHA: > 0 fixed steps of this size, no error control (EPSINT/EPSIND then stop the
  // Newton iterations only); 0: error control.
  double fixed_step = 0.0;
  double initial_step = 0.0;  // > 0: continue with this step (RESTART 0 across blocks)
  // Called after every output time is recorded (index k, data of that state, its linearization
  // or nullptr): progress bars, files written as the run proceeds.
  std::function<void(int, const Data&, const Linearization*)> on_output;
  // Wall-clock seconds the block may take (0: no limit); beyond it TimeLimitError.
  double time_limit = 0.0;
  // Seconds of the same analysis already spent before the run (the model's set-up), counted
  // against time_limit.
  double time_spent = 0.0;
  // Integration steps (accepted and rejected) over the whole block.
  long max_steps = Stepper::kMaxSteps;
  // Planar and spatial trees of rigid bodies take the recursive (articulated-body) right-hand
  // side (tree.hpp, spatial_tree.hpp), other open chains the explicit positions (chain.hpp);
  // false: always the general constraint formulation.
  bool recursive = true;
  // A digital controller (zero-order hold): at the block start and every sample_period after it,
  // on_sample(t, data at t, held) sets the loads (nx) held constant until the next sample; the
  // integrator restarts at every sample (the loads jump there). 0: no controller.
  double sample_period = 0.0;
  std::function<void(double, const Data&, Eigen::VectorXd&)> on_sample;
  // Energy balance (BlockResults::energy): the dissipated power and the external power integrated
  // as two extra states of the integrator, at the cost of O(n) per right-hand side.
  bool energy = false;
  // The start of Newton's iterations on the positions of the general path, for measurements
  // (benchmarks/newton.py): the last solved state advanced by a Taylor step in time of this order
  // (2: its velocities and accelerations; 1: velocities; 0: its positions as they are), and the
  // chord (large systems iterate with the last velocity block while it contracts; false: a
  // fresh factorization in every iteration).
  int predictor_order = 2;
  bool chord = true;
};

// Loads and input motions that vary in time, beyond FORCE's constants and the inputs' constant
// accelerations: evaluated at the time of every stage of the integrator (docs/mechatronics.md).
struct TimeLoads {
  struct LoadTable {  // component j of the table: the load on coordinate coords[j]
    std::vector<int> coords;
    Table table;
  };
  struct InputTable {  // the position of input i (as System::input_cols); rates from its derivatives
    int input;
    Table table;
  };
  std::vector<LoadTable> load_tables;
  std::vector<InputTable> input_tables;
  // Adds loads (nx) at time t, e.g. a Python function: one call per right-hand side.
  std::function<void(double, Eigen::VectorXd&)> load_function;
  bool empty() const { return load_tables.empty() && input_tables.empty() && !load_function; }
};

// Tolerances below this (100 machine epsilons) cannot be met in double precision: EPSINT and
// EPSIND are raised to it with a warning, so that a tiny tolerance cannot make the integrator
// crawl through millions of round-off-limited steps.
constexpr double kMinTolerance = 100.0 * 2.220446049250313e-16;

// A change of integrator within a block (method AUTO): at time t, from one to the other.
struct MethodSwitch {
  double t;
  Method from, to;
};

struct BlockResults {
  Eigen::VectorXd t;
  RowMatrix x, xd, xdd;        // nt x nx
  RowMatrix e, ed, edd, sigma; // nt x ne (sigma complete with the reactions if FORCEMODE ≥ 1)
  RowMatrix reaction;          // nt x nx: reactions on fixed and input coordinates (FORCEMODE ≥ 1)
  std::vector<Linearization> linearizations;  // at every output time if LINE or LINEAR ≥ 1
  // RunOptions::energy: nt x 5, the columns kEnergyColumns (else empty).
  RowMatrix energy;
  // The counters of kRunCounters.
  long rhs_evaluations = 0, steps = 0, accepted = 0, rejected = 0, newton_iterations = 0;
  long jacobians = 0, decompositions = 0;  // the implicit methods only
  Method method = Method::DOP853;          // the integrator the block started with
  std::vector<MethodSwitch> switches;      // method AUTO: the changes of integrator
  double last_step = 0.0;
  double wall_time = 0.0;      // seconds spent in the block
  bool recursive = false;      // the right-hand sides took the recursive path (tree.hpp)
  const char* path = "general";  // the right-hand-side path the run chose (RhsPath::name)
  std::vector<std::string> warnings;
};

// The arrays recorded at every output time, listed once (recording, allocation, the results
// handed to Python and the state given to RunOptions::on_output): Data holds the value at the
// current time, BlockResults one row per output time.
struct OutputArray {
  const char* name;
  const char* what;       // in messages: "the <what> at t = ... are not finite"
  bool per_deformation;   // ne columns (else nx)
  Eigen::VectorXd Data::*now;
  RowMatrix BlockResults::*rows;
};

inline constexpr OutputArray kOutputArrays[] = {
    {"x", "coordinates", false, &Data::x, &BlockResults::x},
    {"xd", "velocities", false, &Data::xd, &BlockResults::xd},
    {"xdd", "accelerations", false, &Data::xdd, &BlockResults::xdd},
    {"e", "deformations", true, &Data::e, &BlockResults::e},
    {"ed", "deformation rates", true, &Data::ed, &BlockResults::ed},
    {"edd", "deformation accelerations", true, &Data::edd, &BlockResults::edd},
    {"sigma", "stresses", true, &Data::sigma, &BlockResults::sigma},
    {"reaction", "reactions", false, &Data::reaction, &BlockResults::reaction},
};

// The counters of a run, listed once (the results handed to Python, spacar._core.run_counters and
// the stats of spacar.simulate): name, member, whether only the implicit methods count it.
struct RunCounter {
  const char* name;
  long BlockResults::*value;
  bool implicit_only;
};

inline constexpr RunCounter kRunCounters[] = {
    {"rhs_evaluations", &BlockResults::rhs_evaluations, false},
    {"steps", &BlockResults::steps, false},
    {"accepted", &BlockResults::accepted, false},
    {"rejected", &BlockResults::rejected, false},
    {"newton_iterations", &BlockResults::newton_iterations, false},
    {"jacobians", &BlockResults::jacobians, true},
    {"decompositions", &BlockResults::decompositions, true},
};

// The columns of BlockResults::energy: kinetic + potential + strain + dissipated − external_work
// is constant. Potential: of gravity; dissipated: ∫ ėᵀ D ė dt; external_work: ∫ of the power of
// FORCE, TORQUEL, the time-dependent loads and the drivers of prescribed inputs (their reactions).
inline constexpr const char* kEnergyColumns[] = {"kinetic", "potential", "strain", "dissipated", "external_work"};

// What changes while a block runs, apart from Data (the state of the mechanism at the current
// time): where Newton starts, the run's choices, the implicit steppers' matrices, the controller's
// held loads, the last kinematic failure. Simulation keeps one; each run sets what it chooses.
struct RunState {
  // A solved state: the starting point of the Newton iterations of later evaluations.
  struct Solved {
    bool valid = false;
    // As an anchor: solved at the accepted state itself, not at the last Newton iterate of an
    // implicit integrator next to it (generalized-α accepts the iterate after its last update).
    bool exact = true;
    double t = 0.0;
    Eigen::VectorXd x, xd, xdd, qhat, angle_ref;
  };
  // Newton starts from the last solved state (base); in a right-hand side, if that fails or
  // leaves the branch of the step start, again from the step start (anchor).
  Solved base, anchor;
  bool in_rhs = false;  // evaluating a right-hand side of the stepper
  int predictor_order = RunOptions().predictor_order;  // of the run (measurements)
  bool chord = RunOptions().chord;
  double fixed_step = 0.0;  // generalized-α's fixed step of the run (BlockPlan::fixed_step)
  Eigen::MatrixXd jacobian_mass;  // M̄ at the state of the last jacobian()
  // The sparse Newton matrix's state (a copy of data at its last refresh) and reduced system.
  std::unique_ptr<Data> newton_data;
  std::unique_ptr<ReducedSystem> newton_system;
  bool newton_singular = false;
  bool newton_factorized = false;  // newton_system factorized at newton_data's state (since its refresh)
  Eigen::VectorXd tree_qdd;  // the tree's q̈ at an output time
  // Message and time of the last right-hand side that failed in Newton, kept while the
  // integration has not passed that time: at a step-size collapse it says that the kinematics
  // has no solution ahead (formulation.md §2.2), whatever rejected the very last attempt.
  std::string kinematic_failure;
  double kinematic_failure_t = 0.0;
  Eigen::VectorXd held;  // loads of the controller held since its last sample (nx), or empty
  int n_energy = 0;      // 2 with RunOptions::energy: the last states of Y (dissipated, external work)
};

// The results of Simulation::rollout: the states at the output times, state by state.
struct RolloutResults {
  RowMatrix q, qd;  // (states · nt) × nd: row s·nt + k holds state s at output time k
  RowMatrix x;      // the same rows × nx: the coordinates' positions, when asked for (else empty)
  std::vector<long> rhs_evaluations, steps, rejected;  // per state integrated
  const char* path = "general";  // the right-hand-side path (RhsPath::name)
  std::vector<std::string> warnings;
  double wall_time = 0.0;  // seconds of the whole rollout
  long failed = -1;        // the state whose integration failed (rows from it cut), or −1
};

class Simulation {
 public:
  // Prepares (first END) and compiles the model; the model must outlive the simulation.
  explicit Simulation(Model& model);

  const System& system() const { return *sys_; }
  Data& data() { return *data_; }

  // Assemble at the block start: inputs at t0, DOFs at their initial values, Newton on the
  // calculable coordinates (with the relaxed limits of an initial assembly). `chain`: the
  // system's open chain (ExplicitChain::detect), solved element by element instead (the
  // general Newton's iteration if it fails there).
  void assemble(ExplicitChain* chain = nullptr);
  // Where Newton's iterations on the positions start (the predictor).
  enum class Start {
    Taylor,    // the last solved state advanced by a second-order Taylor step in time
    Transfer,  // the last solution moved by its transfer function DF (when known, else Taylor)
    Exact      // the last solved state, which holds the exact positions at (t, q): the recursive
               // path's; no polish iteration
  };
  // State at (t, q, q̇) as the integrator needs it: positions, velocities, q̈, accelerations
  // and the complete stresses, without transfer functions (sparse, allocation-free).
  // known_qdd: q̈ already known there (the recursive path's): no equations of motion solved.
  void solve_state(double t, const double* q, const double* qd, Start start = Start::Taylor,
                   const Eigen::VectorXd* known_qdd = nullptr);
  // Complete state at (t, q, q̇): solve_state plus the transfer functions DF, DFe and the
  // reduced mass matrix M̄ (for users, tests and teaching).
  void evaluate(double t, const double* q, const double* qd);
  // The positions at (t, q) with the first-order transfer functions DF, DFe, the rates zero: the
  // kinematic analysis alone (no equations of motion: a mechanism without masses too), from the
  // last solved state predicted by its DF as in move_to's steps.
  void kinematic_state(double t, const Eigen::VectorXd& q);
  // The second-order transfer functions at the state of the last evaluate() or kinematic_state(): column i·n + j of
  // d2f (d2fe) is ∂²x/∂q̂_i∂q̂_j (∂²e/∂q̂_i∂q̂_j) over the n independent coordinates q̂ (the
  // inputs and the DOFs: DF's columns). By polarization of the velocity-product accelerations
  // ẍ(q̂̈ = 0) = q̂̇ᵀ D2F q̂̇, exact as they are quadratic in q̂̇: one velocity solve per pair.
  // The state's rates are left as they were.
  void second_order_transfer(Eigen::MatrixXd& d2f, Eigen::MatrixXd& d2fe);
  // Complete state at (t, q, q̇) reached from the last evaluated (or assembled) state along the
  // straight path in (t, q, q̇), in steps small enough that the first-order predictor keeps the
  // kinematic solution on its branch: one Newton solve from a distant state may converge to
  // another assembly of the mechanism (e.g. a beam folded back on a crank turned by > 90°).
  void move_to(double t, const double* q, const double* qd);
  // Reactions and complete stresses (FORCEMODE) at the state of the last evaluate().
  void forces();
  // Linearized equations at the state of the last evaluate() (computes the forces first).
  Linearization linearize(Linearizer::Differences differences = Linearizer::Differences::Precise);
  // The linearized equations at rest in the nodal coordinates at the state of the last
  // assemble() or evaluate() (Linearizer::compute_nodal); false if that state is not at rest in
  // static equilibrium. Then the saddle-point solves of the eigen-analyses (linearizer()).
  bool linearize_nodal(NodalLinearization& out);
  // The dense reduced matrices at the state of linearize_nodal (at rest in static equilibrium,
  // DOFs q at time t): the positions solved there again (the simulation may have moved since),
  // no equations of motion (q̈ = 0, the static stresses), so a model without mass has them too.
  Linearization linearize_at_rest(double t, const Eigen::VectorXd& q);
  Linearizer& linearizer();
  // Complete state at (t, Y), Y = (q, y, q̇): DOFs, integrated deformations, DOF rates.
  void evaluate_state(double t, const Eigen::VectorXd& Y);
  // Right-hand side of the first-order system Y = (q, y, q̇).
  void rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY);
  // The residual of the reduced equations of motion R = M̄ (q̈ − q̈(Y)) at a trial q̈, without
  // the equations of motion: the accelerations and DF_qᵀ follow block by block on an open chain
  // (ExplicitChain), by solves with the velocity block otherwise. Generalized-α's residual form
  // (Y = (q, q̇): no integrated deformations, no energy states), used on open chains and with the
  // sparse Newton matrix; the state is left without its constraints' stresses.
  bool residual_form() const;
  // Generalized-α's Newton matrix S = M̄ + γ′h (C0 + D0) + β′h² (K0 + G0) solved through the
  // sparse saddle-point system of the nodal coordinates (nodal.hpp) instead of formed from a
  // dense Jacobian, for models of at least kSparseNewtonDofs degrees of freedom (holonomic,
  // without integrated deformations or energy states, not on the recursive path). Its C0 and N0
  // (the velocity- and acceleration-dependent terms) are left out: a simplified Newton matrix,
  // which the iterations' contraction monitors as that of a Jacobian taken at an earlier state.
  bool sparse_newton() const;
  static constexpr int kSparseNewtonDofs = 100;
  void residual(double t, const Eigen::VectorXd& Y, const Eigen::VectorXd& qdd, Eigen::VectorXd& R);
  // Its Jacobian ∂(q̇, ẏ, q̈)/∂(q, y, q̇) at (t, Y) from the linearized equations (simulate_jacobian.cpp).
  void jacobian(double t, const Eigen::VectorXd& Y, Eigen::MatrixXd& J);
  // The state at (q, q̇) by the recursive path: q̈ and the coordinates' positions, velocities and
  // accelerations; false (nothing written) if the system is not a planar or spatial tree of
  // rigid bodies or a body moves no mass. The tree is taken at the solved state of the first
  // call (after assemble(): the assembled state) and kept until the next run.
  bool recursive_state(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, Eigen::VectorXd& qdd,
                       Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd);
  // Why the system is not a tree for the recursive path, at the current (solved) state; empty
  // if it is one.
  std::string recursive_refusal() const;
  // Inverse dynamics at a batch of states (the rows of q, q̇, q̈, one column per DOF): the
  // generalized forces on the DOFs, beyond the model's own loads, gravity, springs and dampers,
  // under which the system has the accelerations q̈ (pinocchio.rnea's τ for a robot). A tree of
  // rigid bodies by the recursive Newton–Euler algorithm, O(N) per state with no Newton
  // iteration; any other system by its reduced equations, M̄ (q̈ − q̈₀), q̈₀ its accelerations
  // under its own loads, each state's positions solved by Newton from the previous state's (so
  // successive rows should be near each other). `path` is set to "tree" or "general".
  RowMatrix inverse_dynamics(const StateRows& q, const StateRows& qd, const StateRows& qdd, std::string& path);
  // The forward dynamics and its derivatives at the states in the rows of q, qd under the extra
  // generalized forces tau (spacar.dynamics_derivatives, as pinocchio.computeABADerivatives): the
  // rows of qdd (nd) and of dq, dqd, dtau (nd × nd each, row k the matrix of state k in row-major
  // order: ∂q̈_i/∂q_j at i·nd + j). On a planar or spatial tree of the recursive path; InputError
  // otherwise.
  void dynamics_derivatives(const StateRows& q, const StateRows& qd, const StateRows& tau, RowMatrix& qdd,
                            RowMatrix& dq, RowMatrix& dqd, RowMatrix& dtau);
  // q̈ of the reduced equations (3.1) with transfer functions at the last evaluated state, the
  // state left as it was: an independent check of the integration path's sparse solve.
  Eigen::VectorXd reduced_accelerations();

  // The entry points of users and the bindings: q and q̇ are checked to have one value per
  // degree of freedom (InputError), then the versions above run (recursive_state checks too).
  void solve_state(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd);
  void evaluate(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd);
  void move_to(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd);

  // Time-dependent loads and input motions for the following runs (checked: InputError).
  void set_time_loads(TimeLoads loads);

  BlockResults run(const RunOptions& options = {});
  // The same, into `res`. If the run fails (an exception), `res` holds what was computed up to
  // the failure: the output times recorded so far (the arrays cut to those rows), the counters
  // and the warnings; the model is not changed.
  void run(BlockResults& res, const RunOptions& options);
  // Write the state reached into the model (coordinates, rates, deformation values, time).
  void store_state();
  // Ready for the model's next block without compiling it again, if the model has not changed
  // since this simulation's last run stored its state and that run took the recursive path (a
  // tree of rigid bodies, no free rotation): the block's start read from the model as a new
  // simulation reads it. A block on the kept tree then starts from the data the last block left
  // (its last output solved the state the model holds: no assembly, no first output solved
  // again); any other block from the data reset (the LUs' pivots kept) and the model's positions.
  // False (nothing done) otherwise: then a new simulation is needed. spacar.simulate keeps the
  // simulation of a model's last run for this: the next block of a 6-link chain costs about a
  // third of a first block beyond its right-hand sides (issue 37).
  bool renew();
  // Whether renew() would succeed now.
  bool renewable() const { return kept_tree_ && model_.revision() == compiled_revision_ + 1; }

  // Runs from many initial states over the same output times (spacar.Rollout): the rows of q0
  // and qd0 (one state each, one column per DOF; the integrated deformations start from the
  // model's) integrated from times.front() through the increasing `times` by options' method,
  // its tolerances EPSINT and EPSIND. The model is assembled and its right-hand-side path chosen
  // (the recursive path of a tree of rigid bodies, when options.recursive) at the first rollout
  // and kept for the next: a rollout then costs its states' integrations alone. On the general
  // path each state's positions are solved by Newton from the assembled ones. `coordinates`: the
  // positions of every coordinate at the output times too. The model is not changed. If a state
  // fails, res holds the states before it and res.failed its index, and the error is rethrown.
  // A free rotation (a floating base) may exchange its dependent Euler parameter within a state's
  // run: the state is recorded in the DOFs it started with all the same. Not with a controller or
  // the energy balance (RunOptions' sample_period, on_sample, energy).
  void rollout(const RowMatrix& q0, const RowMatrix& qd0, const std::vector<double>& times,
               const RunOptions& options, bool coordinates, RolloutResults& res);

 private:
  using Solved = RunState::Solved;
  // A block's run in three stages: plan (the requests checked before any work, the output
  // times), allocate (the result arrays, within the memory limit), integrate (assemble, then
  // the output times reached by integration or, without degrees of freedom, by kinematics).
  struct BlockPlan {
    Settings st;                 // the system's settings, tolerances raised to kMinTolerance
    double t0 = 0.0, t_end = 0.0;
    bool integrate = false;      // degrees of freedom or integrated deformations, and a period
    bool linear = false;         // linearized equations at every output time
    std::vector<double> times;   // the output times, the last exactly t_end
    double fixed_step = 0.0;     // generalized-α's fixed step (planned_fixed_step), 0: error control
  };
  static void check_options(const RunOptions& options);
  BlockPlan plan_block(const RunOptions& options, std::vector<std::string>& warnings) const;
  // How the checks of an integration's period name it: a block's (TIMESTEP's Tp, Tp/n) or a
  // rollout's (the span of its output times).
  struct PeriodNames {
    const char* period_is;  // "TIMESTEP: the period Tp ="
    const char* period;     // "Tp"
    const char* interval;   // "Tp/n"
    const char* run;        // "block"
  };
  static constexpr PeriodNames kBlockNames{"TIMESTEP: the period Tp =", "Tp", "Tp/n", "block"};
  static constexpr PeriodNames kRolloutNames{"the span of the output times T =", "T", "Δt", "state"};
  // tp: the period as given (TIMESTEP's Tp; not t_end − t0, rounded).
  void plan_integration(const RunOptions& options, BlockPlan& plan, double tp, double interval,
                        const PeriodNames& names, std::vector<std::string>& warnings) const;
  static double planned_fixed_step(const RunOptions& options, double t_end, double tp, double interval,
                                   const PeriodNames& names, std::vector<std::string>& warnings);
  void allocate_results(BlockResults& res, const BlockPlan& plan) const;
  // k_out: the output times recorded (also when it throws).
  // renewed, kept_tree: what renew() prepared (the tree of the last run, and whether the data may
  // hold the block's start), taken by run().
  void integrate_block(BlockResults& res, const RunOptions& options, const BlockPlan& plan, int& k_out,
                       bool renewed, std::unique_ptr<RhsPath> kept_tree);
  // The integration of the state Y from plan.t0 through the output times plan.times[k_out…]
  // (output(t, Y) at each) to plan.t_end: segment by segment, for the controller's samples, the
  // repartitions of free rotations and AUTO's switches of method. Counters to res.
  void integrate_segments(BlockResults& res, const RunOptions& options, const BlockPlan& plan, Eigen::VectorXd& Y,
                          int& k_out, const Stepper::Output& output);
  // How a segment ended: the time reached (t_end, or earlier for a repartition or a switch) and
  // whether the integrator asks to hand over to the other one (method AUTO).
  struct SegmentEnd {
    double t;
    bool switch_method;
  };
  // One run of the stepper of `method` (not AUTO) from t towards t_end through `times`, until
  // the end, a repartition of a free rotation or, with `auto_switch`, a change of stiffness.
  // Counters and the last step go to res.
  SegmentEnd integrate_segment(BlockResults& res, const RunOptions& options, Method method, bool auto_switch,
                               const Settings& st, double t, double t_end, double h, Eigen::VectorXd& Y,
                               const std::vector<double>& times, const Stepper::Output& output);
  // What this run offers a stepper (stepper.hpp): the shape of Y and the model's callbacks.
  StepperSetup stepper_setup(const RunOptions& options, bool auto_switch, int n_states);
  void scale_positions(const Eigen::VectorXd& dx, const Eigen::VectorXd& x, Eigen::VectorXd& scaled) const;
  // Whether AUTO takes this model from DOP853 to generalized-α rather than Radau: an undamped
  // structure (some degree-of-freedom deformation has a stiffness, no element has damping) at
  // EPSINT and EPSIND of at least 1e-6, where a second-order method pays (integrate_block).
  bool auto_takes_generalized_alpha() const;
  void record(BlockResults& res, int k);
  // InputError unless q and q̇ have one value per degree of freedom (`what`: the entry point).
  void require_dof_sizes(const char* what, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const;
  // After the integrator gave up: rethrow as a KinematicsError if the kinematics is the cause.
  void explain_collapse(const IntegrationError& err, const Eigen::VectorXd& Y);
  // A free rotation whose dependent Euler parameter has become small, or −1.
  int rotation_to_repartition(const Eigen::VectorXd& Y) const;
  // The tree of rigid bodies of the system, detected at the current state on the first call
  // and kept until the next run; nullptr if the system is not one.
  RecursiveTree* recursive_tree();
  // The system of the partition dependent_ compiled again, with fresh data; the linearizer and
  // the transfer functions of the old one dropped.
  void recompile();
  // Make the largest Euler parameter of that node the dependent one: recompile the system and
  // map the state (t, Y) to the new degrees of freedom.
  void repartition(int which, double t, Eigen::VectorXd& Y);
  void remember(Solved& s) const;
  // solve_state up to the velocities: positions, velocities, no dynamics, not remembered.
  void solve_motion(double t, const double* q, const double* qd, Start start);
  // The kinematics of a right-hand side: a KinematicsError becomes StepRejected (the
  // integrator retries a smaller step) and is remembered for the report.
  template <class F>
  void in_rhs(double t, F&& evaluate);
  // Start the positions from s: its solution advanced by a second-order Taylor step in time.
  void predict_from(const Solved& s, double t, const double* q);
  // The positions just solved against the prediction from the step start (run_.anchor): false if
  // they deviate by more than the predicted motion (another branch of the constraints).
  bool continuous_with_step_start(std::string& why) const;
  // The integrator starts a step at (t, Y): that accepted state becomes the anchor.
  void step_start(double t, const Eigen::VectorXd& Y);
  bool solved_dofs(const Solved& s, const Eigen::VectorXd& Y) const;  // s solved at Y's DOFs
  Model& model_;
  // The X positions before the model's first assembly (empty once it is made, or when the model
  // was prepared before this simulation): the first block warns of the nodes it moved far.
  Eigen::VectorXd x_given_;
  std::map<int, int> dependent_;  // dependent Euler parameter of free rotations, by node
  std::unique_ptr<System> sys_;
  std::unique_ptr<Data> data_;  // replaced when the system is recompiled (repartition)
  RunState run_;
  Eigen::VectorXd qhat_transfer_;  // q̂ at which data holds DF (set by evaluate)
  Eigen::VectorXd predicted_;    // change of the positions predicted by the transfer function
  bool have_transfer_ = false;
  std::unique_ptr<Linearizer> linearizer_;
  // How the states are evaluated (rhs_path.hpp): chosen for a run (RunOptions::recursive), the
  // general path outside runs, except that recursive_state() keeps the tree it took.
  std::unique_ptr<RhsPath> path_ = std::make_unique<GeneralPath>();
  // The tree path of the last run, kept for the next run of the unchanged model (renew()): kept
  // only if that run's store_state() was the one change since the system was compiled or
  // reloaded, so the model is unchanged since while its revision is compiled_revision_ + 1.
  std::unique_ptr<RhsPath> kept_tree_;
  bool renewed_ = false;  // renew() made this simulation ready for the next block, not yet run
  std::uint64_t compiled_revision_ = 0;  // the model's revision the system was compiled or reloaded at
  // The nodes' positions of the model into the data (a new simulation's start).
  void positions_from_model();
  // After renew(), for a block that does not continue on the kept tree: the data reset and the
  // positions read from the model, as a new simulation starts.
  void restart_data();
  bool data_holds_start() const;
  void newton_refresh(double t, const Eigen::VectorXd& Y);
  // The tree's state at (t, Y) into run_.base (positions, rates, accelerations) and qdd; false if a
  // body moves no mass.
  bool tree_state(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& qdd);
  void check_time(double t);       // TimeLimitError past the deadline of the running block
  void require_finite_state(double t) const;  // SpacarError if an output would hold inf or NaN
  TimeLoads timed_;
  // What the first rollout prepared and the next reuse: the assembled positions (Newton's start
  // of every state on the general path, with its data) and the path chosen (swapped into path_
  // while a rollout runs). Dropped by a run and new time loads.
  struct RolloutStart {
    bool ready = false;
    bool recursive = true;  // RunOptions::recursive it was chosen with
    Solved assembled;
    std::unique_ptr<Data> data;  // the assembled data
    std::unique_ptr<RhsPath> path;
    // The partition of the free rotations every state starts in (a state's run may exchange a
    // dependent Euler parameter: the next state starts again in this one), and its DOFs'
    // coordinates (global indices), in which the states are recorded.
    std::map<int, int> dependent;
    std::vector<int> x_dyn;
    // Per DOF coordinate of x_dyn: the coordinate of its free rotation's dependent Euler parameter
    // in that partition (−1: not an Euler parameter). Where that parameter has become negative,
    // the state is recorded with the opposite Euler parameters (the same orientation), so that the
    // recorded q restarts a run in the same orientation.
    std::vector<int> sign_of;
  } rollout_;
  long repartitions_ = 0;  // repartition() calls: a rollout restores its partition after any
  // After a state whose run exchanged a dependent Euler parameter: the system, data and path of
  // the rollout's partition again.
  void restore_rollout_partition(bool recursive);
  BlockPlan plan_rollout(const RowMatrix& q0, const RowMatrix& qd0, const std::vector<double>& times,
                         const RunOptions& options, std::vector<std::string>& warnings) const;
  // The time-dependent loads and inputs at t into data (after set_inputs): input tables replace
  // the inputs' constant-acceleration motion, loads go to Data::time_load.
  void apply_time_loads(double t);
};

}  // namespace spacar
