// Explicit embedded Runge-Kutta integration with step-size control and dense output:
// DOP853 (Hairer, Norsett & Wanner: order 8, error estimators of order 5 and 3, dense output of
// order 7) and DOPRI5 (Dormand & Prince: order 5(4), first-same-as-last, dense output of order 4).
// See E. Hairer, S.P. Norsett, G. Wanner, "Solving Ordinary Differential Equations I",
// Sec. II.4-II.6.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <limits>
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

// RADAU5 is the implicit Radau IIA method of radau5.hpp and GENERALIZED_ALPHA the second-order
// method of generalized_alpha.hpp (classes of their own, not Integrator's). AUTO is
// a choice of the analysis, not an integrator: DOP853 until it detects stiffness, then RADAU5
// until the stiffness goes (simulate.cpp, Simulation::integrate_block).
enum class Method { DOP853, DOPRI5, RADAU5, GENERALIZED_ALPHA, AUTO };
// The method of its name ("dop853", "dopri5", "radau5", "generalized_alpha", "auto"), the one parser of every entry
// point; InputError for any other name.
Method parse_method(const std::string& name);
// The name parse_method reads.
const char* method_name(Method m);
// Every method's name, in the order of the error message ("auto" first): the entry points'
// lists of choices (spacar run, spacar.sweep) come from here.
std::vector<std::string> method_names();

// Shared by the integrators (Integrator, Radau5, GeneralizedAlpha), `who` naming the one in the
// messages: the checks of per-component tolerances (finite, non-negative, not both zero) and of
// the arguments of integrate() (std::invalid_argument; IntegrationError for a non-finite initial
// state), and the "t = ..., step size h = ..." of their error messages.
void check_tolerances(const char* who, int n, const Eigen::VectorXd& rtol, const Eigen::VectorXd& atol);
void check_integration(const char* who, int n, double t0, double t_end, const Eigen::VectorXd& y,
                       const std::vector<double>& touts);
std::string describe_step(double t, double h);

struct IntegratorStats {
  long nfev = 0, nsteps = 0, naccept = 0, nreject = 0;
};

class Integrator {
 public:
  using Rhs = std::function<void(double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy)>;
  using Output = std::function<void(double t, const Eigen::VectorXd& y)>;

  Integrator(int n, Method method = Method::DOP853);

  // Per component; both >= 0 and not both zero (defaults: rtol = atol = 1e-6).
  void set_tolerances(const Eigen::VectorXd& rtol, const Eigen::VectorXd& atol);
  void set_max_step(double hmax);   // default +inf
  // Steps (accepted and rejected) one integrate() call may take before IntegrationError
  // (default kMaxSteps).
  void set_max_steps(long n);
  static constexpr long kMaxSteps = 10000000;
  // Smallest step size the integrator takes at time t (below it: step size underflow).
  static double min_step(double t);
  // 0 = automatic estimate (Hairer's hinit); used to continue across blocks (RESTART 0).
  void set_initial_step(double h);
  // Step proposed after the last accepted step, to continue later with set_initial_step.
  double last_step() const;

  // Integrate y from t0 to t_end (t_end >= t0). For every t_k in touts (sorted ascending, within
  // [t0, t_end]) call out(t_k, y(t_k)) using the dense output (t_k == t0: the initial value;
  // t_k == t_end: exactly the final state). The last step is clipped to end exactly at t_end.
  // On return y holds y(t_end); if IntegrationError is thrown, y holds the last accepted state.
  // Returns the time reached: t_end, or earlier if the stop condition asked to stop.
  double integrate(const Rhs& f, double t0, double t_end, Eigen::VectorXd& y,
                   const std::vector<double>& touts, const Output& out);

  // Checked after every accepted step (t, y): returning true ends integrate() there, e.g. to
  // change the coordinate partition of the model and continue.
  using StopCondition = std::function<bool(double t, const Eigen::VectorXd& y)>;
  void set_stop_condition(StopCondition stop);

  // Called before every attempted step with its start (t, y), the last accepted state, at which
  // the right-hand side has just been evaluated (also again after a rejection).
  using StepStart = std::function<void(double t, const Eigen::VectorXd& y)>;
  void set_step_start(StepStart start);

  const IntegratorStats& stats() const;   // cumulative over all integrate calls

  // Stiffness detection (Hairer's test in his codes DOP853 and DOPRI5): after every accepted
  // step, h|λ| is estimated as h ‖f(t+h, y_new) − f(t+h, Y)‖ / ‖y_new − Y‖ from the last two
  // evaluations at t + h (Y: the argument of the last stage, at c = 1), which differ by a
  // small perturbation of the solution: the quotient is a Rayleigh-like estimate of the
  // dominant eigenvalue of ∂f/∂y along it. A step with h|λ| above the method's bound (the edge of
  // its stability region on the negative real axis: 6.1 for DOP853, 3.25 for DOPRI5) counts as
  // stiff: its size is set by stability, not by accuracy. After kStiffSteps such steps, not
  // interrupted by kNonstiffSteps others in a row, the problem is stiff; integrate() stops there
  // (as with the stop condition) and stiffness_detected() says so, provided at least
  // `min_steps_ahead` steps of the current size remain to t_end: a change of method costs a
  // Jacobian and factorizations and pays only ahead of many stability-limited steps. (Hairer's
  // codes make the first test only after 1000 steps, then every 1000th until a first stiff one;
  // here every step is tested, two norms beside 12 right-hand sides, so that an expensive stiff
  // problem is recognized after a few tens of steps, and the steps ahead decide whether to act.)
  void set_stiffness_detection(bool on, double min_steps_ahead = 0.0);
  bool stiffness_detected() const;   // the last integrate() stopped because of stiffness
  double stiffness_estimate() const;  // h|λ| of the last accepted step (0 if not detecting)
  static double stiffness_bound(Method m);  // that bound for h|λ| (DOP853 or DOPRI5)
  static constexpr int kStiffSteps = 15, kNonstiffSteps = 6;

 private:
  enum class Attempt { Accepted, ErrorTooLarge, Failed };

  bool eval(const Rhs& f, double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy);
  bool eval_stages(const Rhs& f, double t, double h, const Eigen::VectorXd& y, int first, int last);
  double initial_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y);
  Attempt attempt_step(const Rhs& f, double t, double h, double t_new, const Eigen::VectorXd& y,
                       bool dense);
  void estimate_stiffness(double h);
  bool stiff_after_step();
  double error_norm(double h);
  double step_factor() const;
  bool build_dense(const Rhs& f, double t, double h, const Eigen::VectorXd& y);
  void dense_value(double theta, const Eigen::VectorXd& y_old);
  size_t emit_outputs(const std::vector<double>& touts, size_t next, double t, double h,
                      double t_new, const Eigen::VectorXd& y, const Output& out);

  int n_;
  Method method_;
  Eigen::VectorXd rtol_, atol_;
  double hmax_;
  long max_steps_ = kMaxSteps;
  double h_initial_ = 0.0;
  double h_last_ = 0.0;
  double err_ = 0.0;                 // error norm of the last attempted step
  std::string failure_;              // why the last step was rejected, for error messages
  StopCondition stop_;
  StepStart step_start_;
  IntegratorStats stats_;
  bool detect_stiffness_ = false, stiff_ = false;
  double hlamb_ = 0.0, min_steps_ahead_ = 0.0;
  int stiff_steps_ = 0, nonstiff_steps_ = 0;   // Hairer's IASTI and NONSTI
  // Work space, allocated once so that the step loop never touches the heap.
  std::vector<Eigen::VectorXd> k_;       // stages; k_[0] = f(t, y)
  std::vector<Eigen::VectorXd> dense_;   // coefficients of the dense-output polynomial
  Eigen::VectorXd y_stage_, y_new_, scale_, err_a_, err_b_, y_out_;
};

// The start of integrate(), shared by the integrators: the outputs at t0 (returns the index of
// the first output time after it), ...
inline size_t outputs_at_start(const std::vector<double>& touts, double t0, const Eigen::VectorXd& y,
                               const Integrator::Output& out) {
  size_t next = 0;
  for (; next < touts.size() && touts[next] == t0; ++next) out(t0, y);
  return next;
}

// ... and the right-hand side at the initial state: `evaluate()` makes it (false: non-finite
// values, the reason in `failure`); that, or a StepRejected from the right-hand side, ends the
// integration with IntegrationError "<who>: cannot start, ...".
template <class Evaluate>
void evaluate_start(const char* who, double t0, std::string& failure, Evaluate&& evaluate) {
  bool ok = false;
  try {
    ok = evaluate();
  } catch (const StepRejected& e) {
    failure = e.what();
  }
  if (!ok)
    throw IntegrationError(std::string(who) + ": cannot start, rhs failed at the initial state (" + failure + ") at " +
                           describe_step(t0, 0.0));
}

}  // namespace spacar
