// The interface of the time integrators: one base class, Stepper, that owns what every method
// has (tolerances per component, maximum step, step limit, initial step, stop condition, step-start
// callback, Jacobian callback, counters) and the loop of integrate() with its guards and outputs;
// a method supplies the hooks of that loop (its start, its first step, one attempted step) in a
// file of its own, and one row of the method table (stepper.cpp). docs/architecture.md, "Adding an
// integrator", walks through it.
//
// The methods: DOP853 and DOPRI5 (integrator.hpp), RADAU5 (radau5.hpp), GENERALIZED_ALPHA
// (generalized_alpha.hpp). AUTO is a choice of the analysis between two of them, not a stepper
// (Simulation::integrate_block).
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace spacar {

// Constants of the step-size control and of the simplified Newton iterations that the
// integrators share (Hairer's values in DOP853 and RADAU5).
constexpr double kStepSafety = 0.9;          // safety factor of the step-size control
constexpr int kMaxNewton = 7;                // RADAU5's NIT; generalized-α's too
constexpr double kMinError = 1e-10;          // floor of a scaled error in the step-size formulas
constexpr double kRound = std::numeric_limits<double>::epsilon();  // the unit round-off

// Thrown by a right-hand side to ask the integrator to reject the current step and retry with half
// the step (e.g. Newton iteration failed inside the rhs).
struct StepRejected : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown when the integrator cannot continue (step size underflow, too many steps, non-finite
// state). Message says time, step size and why.
struct IntegrationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class Method { DOP853, DOPRI5, RADAU5, GENERALIZED_ALPHA, AUTO };
// The method of its name ("dop853", "dopri5", "radau5", "generalized_alpha", "auto"), the one parser of every entry
// point; InputError for any other name.
Method parse_method(const std::string& name);
// The name parse_method reads.
const char* method_name(Method m);
// Every method's name, in the order of the error message ("auto" first): the entry points'
// lists of choices (spacar run, spacar.sweep) come from here.
std::vector<std::string> method_names();
// The names of the methods that take a Jacobian (their runs report Jacobians and factorizations).
std::vector<std::string> implicit_method_names();

// The "t = ..., step size h = ..." of the integrators' error messages.
std::string describe_step(double t, double h);

// Counters, cumulative over all integrate() calls of a stepper. The explicit methods leave the
// Newton ones at zero.
struct StepperStats {
  long nfev = 0, nsteps = 0, naccept = 0, nreject = 0;
  long njev = 0;      // Jacobian evaluations (or refreshes of a Newton system)
  long ndec = 0;      // factorizations of the Newton matrix (Radau5: one real and one complex each)
  long nnewton = 0;   // simplified Newton iterations
  long nresidual = 0; // of nfev, residuals of the residual form (GeneralizedAlpha::set_residual)
};

struct StepperSetup;

class Stepper {
 public:
  using Rhs = std::function<void(double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy)>;
  using Output = std::function<void(double t, const Eigen::VectorXd& y)>;
  // Checked after every accepted step (t, y): returning true ends integrate() there, e.g. to
  // change the coordinate partition of the model and continue.
  using StopCondition = std::function<bool(double t, const Eigen::VectorXd& y)>;
  // Called before every attempted step with its start (t, y), the last accepted state, at which
  // the right-hand side has just been evaluated (also again after a rejection).
  using StepStart = std::function<void(double t, const Eigen::VectorXd& y)>;
  // J = ∂f/∂y at (t, y), n x n. May throw StepRejected like the rhs.
  using Jacobian = std::function<void(double t, const Eigen::VectorXd& y, Eigen::MatrixXd& J)>;

  virtual ~Stepper() = default;
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  // Per component; both >= 0 and not both zero (defaults: rtol = atol = 1e-6). A method may map
  // them to its error estimate (Radau5).
  void set_tolerances(const Eigen::VectorXd& rtol, const Eigen::VectorXd& atol);
  void set_max_step(double hmax);  // default +inf
  // The smallest change of a state (in its own unit) the implicit methods' Newton iterations
  // resolve (default 0). They stop below it however small the tolerance of a component near
  // zero: at EPS 10⁻¹⁰ the absolute tolerance 10⁻³ EPS of a deformation rate asks for 10⁻¹³,
  // under the 2·10⁻¹² at which a spinning beam's iterates settle, and the steps were halved to
  // 10⁻⁸ s to pass (issue 36: a 16-beam spin-up stalled at 0.49 s).
  void set_newton_floor(double floor);
  // Steps (accepted and rejected) one integrate() call may take before IntegrationError
  // (default kMaxSteps).
  void set_max_steps(long n);
  static constexpr long kMaxSteps = 10000000;
  // Smallest step size the integrator takes at time t (below it: step size underflow).
  static double min_step(double t);
  // 0 = automatic estimate; used to continue across blocks (RESTART 0).
  void set_initial_step(double h);
  // Step proposed after the last accepted step, to continue later with set_initial_step.
  double last_step() const { return h_last_; }
  void set_stop_condition(StopCondition stop);
  void set_step_start(StepStart start);
  // Required by the implicit methods before integrate(); the explicit ones do not call it.
  void set_jacobian(Jacobian jac);

  // Integrate y from t0 to t_end (t_end >= t0). For every t_k in touts (sorted ascending, within
  // [t0, t_end]) call out(t_k, y(t_k)) using the method's dense output (t_k == t0: the initial
  // value; t_k == t_end: exactly the final state). The last step is clipped to end exactly at
  // t_end. On return y holds y(t_end); if IntegrationError is thrown, y holds the last accepted
  // state. Returns the time reached: t_end, or earlier if the stop condition (or wants_switch)
  // stopped it.
  double integrate(const Rhs& f, double t0, double t_end, Eigen::VectorXd& y, const std::vector<double>& touts,
                   const Output& out);

  const StepperStats& stats() const { return stats_; }
  // The last integrate() stopped to hand over to the other method of AUTO: the explicit method
  // found the problem stiff, Radau5 found it no longer stiff.
  bool wants_switch() const { return switch_; }

 protected:
  Stepper(const char* name, int n);

  // The outputs of one integrate() call: out(t_k, y(t_k)) for touts[next] on.
  struct Outputs {
    const std::vector<double>& touts;
    size_t next;
    const Output& out;
  };
  enum class Outcome {
    Accepted,  // y and the outputs up to the step's end are done; h: the next step proposed
    Rejected,  // h: the size to try again with
    Retry,     // the same step again, not counted as an attempt (generalized-α's other form)
  };

  // The hooks of integrate(), in the order it calls them.
  // The callbacks the method needs are set (else std::invalid_argument).
  virtual void check_ready() const {}
  // Forget the state of an earlier integrate() call (before the outputs at t0).
  virtual void begin() {}
  // The right-hand side at the initial state, into the method's own storage (false: non-finite
  // values, the reason in failure_).
  virtual bool start(const Rhs& f, double t0, const Eigen::VectorXd& y) = 0;
  // The first step size (within hmax).
  virtual double first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) = 0;
  // One attempt of the step t → t_new = t + h_try. A StepRejected from the right-hand side must
  // be caught here (why in failure_).
  virtual Outcome step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y, Outputs& outputs,
                       double& h) = 0;
  // After an accepted step (t, its next step h): stop here for AUTO (then wants_switch())?
  virtual bool switch_after_step(double /*t*/, double /*t_end*/, double /*h*/) { return false; }
  // The tolerances were set (a method that maps them does so here, in rtol_ and atol_).
  virtual void tolerances_set() {}

  // The right-hand side with the count and the check of its size and values (false: non-finite;
  // a StepRejected passes through).
  bool eval(const Rhs& f, double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy);

  // Simplified Newton's contraction, Hairer's test in RADAU5 (the implicit methods share it):
  // after iteration it ≥ 2 with the scaled increment dn (dn_old the one before; thq_old carried
  // between iterations), the rate theta_ and faccon_. Diverges when theta_ ≥ 0.99; TooSlow when
  // the iterations left cannot reach `tolerance`, with slow_factor_ for the smaller retry;
  // failure_ says which.
  enum class Contraction { Converging, Diverges, TooSlow };
  Contraction newton_contraction(int it, double dn, double dn_old, double& thq_old, double tolerance);
  double theta_ = 0.0, faccon_ = 1.0, slow_factor_ = 0.5;  // Hairer's THETA, FACCON

  const char* name_;  // in the messages: "Integrator", "Radau5", "GeneralizedAlpha"
  int n_;
  Eigen::VectorXd rtol_, atol_;
  double newton_floor_ = 0.0;
  // The divisors of Newton's increments: the error's scale, but not below newton_floor_ / tolerance
  // (the tolerance of the iteration's stop, in units of the scale).
  void newton_divisors(const Eigen::VectorXd& scale, double tolerance, Eigen::VectorXd& divisors) const;
  double hmax_ = std::numeric_limits<double>::infinity();
  long max_steps_ = kMaxSteps;
  double h_initial_ = 0.0, h_last_ = 0.0;
  StopCondition stop_;
  StepStart step_start_;
  Jacobian jac_;
  StepperStats stats_;
  std::string failure_;  // why the last step was rejected, for error messages
  bool switch_ = false;
};

// The residual form of generalized-α's Newton iterations (GeneralizedAlpha::set_residual).
using Residual = std::function<void(double t, const Eigen::VectorXd& y, const Eigen::VectorXd& D, Eigen::VectorXd& R)>;
using ResidualWeight = std::function<void(Eigen::MatrixXd& W)>;
// A Newton matrix of the caller's own (GeneralizedAlpha::set_newton_system).
struct NewtonSystem {
  std::function<void(double t, const Eigen::VectorXd& y)> refresh;
  std::function<void(double gh, double bh2)> factorize;
  std::function<void(const Eigen::VectorXd& r, Eigen::VectorXd& x)> solve;
  // x = S⁻¹ W_v v; with scaled_dx, also the motion of the coordinates Z x, scaled as
  // StepperSetup::position_error's (generalized-α's error estimate: no second transfer).
  std::function<void(const Eigen::VectorXd& v, Eigen::VectorXd& x, Eigen::VectorXd* scaled_dx)> solve_weighted;
};

// What a run offers the stepper of a segment: the shape of the state and the model's callbacks.
// Each method takes what it uses (its make function); the run then sets the tolerances, steps and
// callbacks common to all (Simulation::run_segment).
struct StepperSetup {
  int n = 0;            // states Y = (q, y, q̇, w)
  int positions = 0;    // m: the first m states are positions (the DOFs q) ...
  int rate_offset = 0;  // ... whose rates q̇ are the m states from here on (the last m: no
                        // quadrature states after them)
  Stepper::Jacobian jacobian;
  Residual residual;          // optional: the residual form of the equations of motion ...
  ResidualWeight weight;      // ... and its weight W_v = M̄
  NewtonSystem newton;        // optional: a sparse Newton matrix (large models)
  double rho_inf = 0.9;       // generalized-α's spectral radius at infinite frequency
  double fixed_step = 0.0;    // generalized-α: fixed steps without error control (0: controlled)
  // Optional, generalized-α: the error of the positions q mapped to the coordinates the model
  // moves, each divided by (10⁻³ + |x|): the step control then bounds the nodal positions' error
  // as well as the DOFs' (a flexible beam's DOFs are deformations, which its tip adds up).
  std::function<void(const Eigen::VectorXd& dq, Eigen::VectorXd& scaled_dx)> position_error;
  // Radau5 keeps a Jacobian while Newton contracts at least this fast (Hairer's default 0.001;
  // a run's Jacobian is a linearization costing several right-hand sides per DOF).
  double jacobian_reuse = 0.1;
  // AUTO: the explicit method stops where it finds the problem stiff, Radau5 where it finds it
  // no longer stiff (wants_switch).
  bool auto_switch = false;
  // AUTO leaves DOP853 for Radau only when, at the stiffness detected, at least this many steps
  // of DOP853's current size remain in the block (Hairer's NSTIFF: his DOP853 looks for
  // stiffness only after 1000 steps). A short stiff stretch costs DOP853 little, and where the
  // stiff modes are excited (the manual's slider-crank) Radau's steps are no longer than DOP853's.
  // (500 where AUTO goes to generalized-α: Simulation::stepper_setup.)
  double stiff_steps_ahead = 1000.0;
  // AUTO: h|λ| beyond which a DOP853 step counts as stiff (0: the edge of its stability region,
  // 6.1). An undamped structure takes 1: a step shorter than a sixth of its fastest period is
  // set by that vibration, which generalized-α need not resolve (Simulation::integrate_block).
  double stiff_bound = 0.0;
  // AUTO: the stiff DOP853 steps that make the problem stiff (Hairer's 15; 5 towards
  // generalized-α, whose bound of 1 sits well under the 2–5 of a structure's DOP853 steps).
  int stiff_count = 15;
  // AUTO returns from Radau to DOP853 only where DOP853 would be stable at this many times
  // Radau's step (LSODA's RATIO, Petzold 1983: it pays for DOP853's 12 right-hand sides per step
  // against Radau's 4 to 10 and keeps the two from alternating).
  double explicit_gain = 5.0;
};

// The stepper of a method (not AUTO) for a segment of a run.
std::unique_ptr<Stepper> make_stepper(Method method, const StepperSetup& setup);

}  // namespace spacar
