// One analysis block (what SPACAR does at an END): assemble the mechanism, then integrate the
// reduced equations of motion over the TIMESTEP interval in C++ with error control, or, without
// degrees of freedom, run the kinematic analysis at every output time. Results are recorded at
// the output times; the state reached is stored back into the model (for the dump and the
// next block).
#pragma once

#include <Eigen/Dense>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "spacar/data.hpp"
#include "spacar/integrator.hpp"
#include "spacar/linearize.hpp"
#include "spacar/model.hpp"
#include "spacar/system.hpp"

namespace spacar {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct RunOptions {
  Method method = Method::DOP853;
  double initial_step = 0.0;  // > 0: continue with this step (RESTART 0 across blocks)
  // Called after every output time is recorded (index k, data of that state): progress bars,
  // files written as the run proceeds.
  std::function<void(int, const Data&)> on_output;
  // Wall-clock seconds the block may take (0: no limit); beyond it TimeLimitError.
  double time_limit = 0.0;
  // Integration steps (accepted and rejected) over the whole block.
  long max_steps = Integrator::kMaxSteps;
};

// Tolerances below this (100 machine epsilons) cannot be met in double precision: EPSINT and
// EPSIND are raised to it with a warning, so that a tiny tolerance cannot make the integrator
// crawl through millions of round-off-limited steps.
constexpr double kMinTolerance = 100.0 * 2.220446049250313e-16;

struct BlockResults {
  Eigen::VectorXd t;
  RowMatrix x, xd, xdd;        // nt x nx
  RowMatrix e, ed, edd, sigma; // nt x ne (sigma complete with the reactions if FORCEMODE ≥ 1)
  RowMatrix reaction;          // nt x nx: reactions on fixed and input coordinates (FORCEMODE ≥ 1)
  std::vector<Linearization> linearizations;  // at every output time if LINE or LINEAR ≥ 1
  long rhs_evaluations = 0, steps = 0, accepted = 0, rejected = 0, newton_iterations = 0;
  double last_step = 0.0;
  double wall_time = 0.0;      // seconds spent in the block
  std::vector<std::string> warnings;
};

class Simulation {
 public:
  // Prepares (first END) and compiles the model; the model must outlive the simulation.
  explicit Simulation(Model& model);

  const System& system() const { return *sys_; }
  Data& data() { return data_; }

  // Assemble at the block start: inputs at t0, DOFs at their initial values, Newton on the
  // calculable coordinates (with the relaxed limits of an initial assembly).
  void assemble();
  // Complete state at (t, q, q̇): positions, DF, velocities, q̈, accelerations, stresses.
  void evaluate(double t, const double* q, const double* qd);
  // Reactions and complete stresses (FORCEMODE) at the state of the last evaluate().
  void forces();
  // Linearized equations at the state of the last evaluate() (computes the forces first).
  Linearization linearize();
  // Right-hand side of the first-order system Y = (q, q̇).
  void rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY);

  BlockResults run(const RunOptions& options = {});
  // The same, into `res`. If the run fails (an exception), `res` holds what was computed up to
  // the failure: the output times recorded so far (the arrays cut to those rows), the counters
  // and the warnings; the model is not changed.
  void run(BlockResults& res, const RunOptions& options);
  // Write the state reached into the model (coordinates, rates, deformation values, time).
  void store_state();

 private:
  void record(BlockResults& res, int k);
  // A free rotation whose dependent Euler parameter has become small, or −1.
  int rotation_to_repartition(const Eigen::VectorXd& Y) const;
  // Make the largest Euler parameter of that node the dependent one: recompile the system and
  // map the state (t, Y) to the new degrees of freedom.
  void repartition(int which, double t, Eigen::VectorXd& Y);
  Model& model_;
  std::map<int, int> dependent_;  // dependent Euler parameter of free rotations, by node
  std::unique_ptr<System> sys_;
  Data data_;
  Eigen::VectorXd x_base_, qhat_base_, predictor_;
  std::unique_ptr<Linearizer> linearizer_;
  bool have_base_ = false;
  std::string kinematic_failure_;  // message of the last right-hand side that failed in Newton
  void check_time(double t);       // TimeLimitError past the deadline of the running block
  void require_finite_state(double t) const;  // SpacarError if an output would hold inf or NaN
  bool has_deadline_ = false;
  std::chrono::steady_clock::time_point deadline_;
  double time_limit_ = 0.0;
};

}  // namespace spacar
