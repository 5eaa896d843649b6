// One analysis block (what SPACAR does at an END): assemble the mechanism, then integrate the
// reduced equations of motion over the TIMESTEP interval in C++ with error control, or, without
// degrees of freedom, run the kinematic analysis at every output time. Results are recorded at
// the output times; the state reached is stored back into the model (for the dump and the
// next block).
#pragma once

#include <Eigen/Dense>
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
};

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
  // Complete state at (t, Y), Y = (q, y, q̇): DOFs, integrated deformations, DOF rates.
  void evaluate_state(double t, const Eigen::VectorXd& Y);
  // Right-hand side of the first-order system Y = (q, y, q̇).
  void rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY);

  BlockResults run(const RunOptions& options = {});
  // Write the state reached into the model (coordinates, rates, deformation values, time).
  void store_state();

 private:
  void record(BlockResults& res, int k);
  // A free rotation whose dependent Euler parameter has become small, or −1.
  int rotation_to_repartition(const Eigen::VectorXd& Y) const;
  // Make the largest Euler parameter of that node the dependent one: recompile the system and
  // map the state (t, Y) to the new degrees of freedom.
  void repartition(int which, double t, Eigen::VectorXd& Y);
  // A solved state, kept as the starting point of the Newton iteration of later evaluations.
  struct Solution {
    double t = 0.0;
    Eigen::VectorXd Y;                // integrator state of a right-hand side (else empty)
    Eigen::VectorXd x, qhat, angles;  // positions, q̂, branches of the angle-type deformations
    Eigen::MatrixXd DF;               // first-order transfer function there (empty: not computed)
  };
  Solution solution(double t, bool with_DF) const;
  // The integrator starts a step at (t, Y): that accepted state becomes the base of the Newton
  // iterations until the next step.
  void step_start(double t, const Eigen::VectorXd& Y);
  void forget_solutions();
  bool continuous_with_step_start(std::string& why) const;
  Model& model_;
  std::map<int, int> dependent_;  // dependent Euler parameter of free rotations, by node
  std::unique_ptr<System> sys_;
  Data data_;
  // Newton starts from the last solution advanced with its DF (the predictor); in a right-hand
  // side, if that fails or leaves the branch of the step start, again from the step start
  // (anchor_), see evaluate().
  Solution last_, anchor_;
  bool have_last_ = false, have_anchor_ = false;
  static constexpr size_t kRecent = 32;  // recent right-hand sides, to find the step start
  std::vector<Solution> recent_;
  size_t recent_next_ = 0;
  Eigen::VectorXd predictor_;
  mutable Eigen::VectorXd predictor_anchor_;
  bool in_rhs_ = false;            // evaluating a right-hand side of the integrator
  std::unique_ptr<Linearizer> linearizer_;
  // Message and time of the last right-hand side that failed in Newton, kept while the
  // integration has not passed that time: at a step-size collapse it says that the kinematics
  // has no solution ahead (formulation.md §2.2), whatever rejected the very last attempt.
  std::string kinematic_failure_;
  double kinematic_failure_t_ = 0.0;
};

}  // namespace spacar
