// Explicit embedded Runge-Kutta integration with step-size control and dense output:
// DOP853 (Hairer, Norsett & Wanner: order 8, error estimators of order 5 and 3, dense output of
// order 7) and DOPRI5 (Dormand & Prince: order 5(4), first-same-as-last, dense output of order 4).
// See E. Hairer, S.P. Norsett, G. Wanner, "Solving Ordinary Differential Equations I",
// Sec. II.4-II.6.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "spacar/integrators/stepper.hpp"

namespace spacar {

class Integrator : public Stepper {
 public:
  explicit Integrator(int n, Method method = Method::DOP853);
  // The stepper of DOP853 or DOPRI5 for a run (the method table, stepper.cpp).
  static std::unique_ptr<Stepper> make(Method method, const StepperSetup& setup);

  // Stiffness detection (Hairer's test in his codes DOP853 and DOPRI5): after every accepted
  // step, h|λ| is estimated as h ‖f(t+h, y_new) − f(t+h, Y)‖ / ‖y_new − Y‖ from the last two
  // evaluations at t + h (Y: the argument of the last stage, at c = 1), which differ by a
  // small perturbation of the solution: the quotient is a Rayleigh-like estimate of the
  // dominant eigenvalue of ∂f/∂y along it. A step with h|λ| above the method's bound (the edge of
  // its stability region on the negative real axis: 6.1 for DOP853, 3.25 for DOPRI5) counts as
  // stiff: its size is set by stability, not by accuracy. After kStiffSteps such steps (or `count`), not
  // interrupted by kNonstiffSteps others in a row, the problem is stiff; integrate() stops there
  // (as with the stop condition) and wants_switch() says so, provided at least
  // `min_steps_ahead` steps of the current size remain to t_end: a change of method costs a
  // Jacobian and factorizations and pays only ahead of many stability-limited steps. (Hairer's
  // codes make the first test only after 1000 steps, then every 1000th until a first stiff one;
  // here every step is tested, two norms beside 12 right-hand sides, so that an expensive stiff
  // problem is recognized after a few tens of steps, and the steps ahead decide whether to act.)
  // bound: h|λ| beyond which a step counts as stiff (0: the edge of the stability region);
  // count: the stiff steps it takes (kStiffSteps, Hairer's).
  void set_stiffness_detection(bool on, double min_steps_ahead = 0.0, double bound = 0.0, int count = kStiffSteps);
  double stiffness_estimate() const;  // h|λ| of the last accepted step (0 if not detecting)
  static double stiffness_bound(Method m);  // that bound for h|λ| (DOP853 or DOPRI5)
  static constexpr int kStiffSteps = 15, kNonstiffSteps = 6;

 private:
  enum class Attempt { Accepted, ErrorTooLarge, Failed };

  // The hooks of Stepper::integrate.
  void begin() override;
  bool start(const Rhs& f, double t0, const Eigen::VectorXd& y) override;
  double first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) override;
  Outcome step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y, Outputs& outputs,
               double& h) override;
  bool switch_after_step(double t, double t_end, double h) override;

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

  Method method_;
  double err_ = 0.0;                 // error norm of the last attempted step
  bool rejected_ = false;            // the previous attempt failed: do not grow the step right after
  bool detect_stiffness_ = false;
  double hlamb_ = 0.0, min_steps_ahead_ = 0.0, stiff_bound_ = 0.0;
  int stiff_steps_ = 0, nonstiff_steps_ = 0;   // Hairer's IASTI and NONSTI
  int stiff_count_ = kStiffSteps;
  // Work space, allocated once so that the step loop never touches the heap.
  std::vector<Eigen::VectorXd> k_;       // stages; k_[0] = f(t, y)
  std::vector<Eigen::VectorXd> dense_;   // coefficients of the dense-output polynomial
  Eigen::VectorXd y_stage_, y_new_, scale_, err_a_, err_b_, y_out_;
};

}  // namespace spacar
