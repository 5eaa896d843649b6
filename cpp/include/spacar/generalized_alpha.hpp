// Generalized-α integration of second-order equations of motion (Chung & Hulbert 1993) in the
// form Arnold & Brüls (2007) give it for y' = f(t, y) written as first-order equations, with
// local-error step control in the manner of Zienkiewicz & Xie (1991).
//
// The state y holds m positions q (its first m components), their rates v (the m components from
// rate_offset on, as (q, y, q̇) of the reduced equations of motion) and any other first-order
// states; Z = y[m:n] collects all but the positions, with derivatives D = f_Z(t, y). A step
// solves for D at its end, with an acceleration-like variable A (of Z) carried between steps:
//   (1 − αm) A⁺ + αm A = (1 − αf) D⁺ + αf D
//   Z⁺ = Z + h ((1 − γ) A + γ A⁺)
//   q⁺ = q + h v + h² ((½ − β) a + β a⁺)          (a: the rate part of A)
// with D⁺ = f_Z(t + h, q⁺, Z⁺). The parameters follow from the spectral radius ρ∞ at infinite
// frequency: ρ∞ = 1 conserves the amplitude of every mode (the trapezoidal rule), smaller values
// damp the highest ones (ρ∞ = 0: annihilated in one step) while keeping second order.
//
// The interface has the shape of Radau5's (radau5.hpp): per-component tolerances, maximum step,
// step limit, initial step, stop condition, step-start callback, dense output at the output
// times, and the Jacobian ∂f/∂y from a callback, reused over steps while the simplified Newton
// iterations converge well. The Newton matrix I − γ' h ∂f_Z/∂Z − β' h² ∂f_Z/∂q (size n − m) is
// factorized once per step size.
//
// Error control: the local error of the positions, q⁺ minus the cubic Taylor step
// q + h v + h² (D/3 + D⁺/6) of their accelerations, and of the first-order states other than the
// rates, the trapezoidal rule's h³ y'''/12 from divided differences of D. The rates themselves are
// not controlled (their error appears in the positions one step later); this is what lets the
// step grow past the periods of high-frequency modes of negligible amplitude, the point of the
// method for flexible links.
#pragma once

#include <Eigen/Dense>
#include <string>

#include "spacar/integrator.hpp"
#include "spacar/radau5.hpp"

namespace spacar {

class GeneralizedAlpha {
 public:
  using Rhs = Integrator::Rhs;
  using Output = Integrator::Output;
  using StopCondition = Integrator::StopCondition;
  using StepStart = Integrator::StepStart;
  using Jacobian = Radau5::Jacobian;

  // n states, of which the first m are positions with rates at rate_offset .. rate_offset + m − 1
  // (m ≤ rate_offset ≤ n − m); rho_inf in [0, 1].
  GeneralizedAlpha(int n, int m, int rate_offset, double rho_inf);

  // Per component, sc = atol + rtol |y|, as for Integrator (not mapped: the method has order 2
  // and the global error follows rtol roughly in proportion).
  void set_tolerances(const Eigen::VectorXd& rtol, const Eigen::VectorXd& atol);
  void set_max_step(double hmax);
  void set_max_steps(long n);
  void set_initial_step(double h);  // 0 = automatic
  double last_step() const;
  void set_stop_condition(StopCondition stop);
  void set_step_start(StepStart start);
  void set_jacobian(Jacobian jac);  // required before integrate()
  // The residual form of the Newton iterations (optional): R = W(y) (D − f_Z(t, y)) for a trial
  // D of Z, with W the identity except in the rates' rows, where it is a matrix W_v (m x m) of
  // the positions (the reduced mass matrix M̄(q) of equations of motion M̄ q̈ = r(q, q̇)). Where
  // the residual costs less than f_Z (no solve with M̄), the iterations use it with the Newton
  // matrix W_v N, W_v taken at the Jacobian's state: the same increments to first order.
  // `weight` gives W_v there, after each call of the Jacobian.
  using Residual = std::function<void(double t, const Eigen::VectorXd& y, const Eigen::VectorXd& D, Eigen::VectorXd& R)>;
  using Weight = std::function<void(Eigen::MatrixXd& W)>;
  void set_residual(Residual residual, Weight weight);
  // A Newton matrix of the caller's own instead of the dense one from the Jacobian (large models,
  // sparse): where the integrator would take a Jacobian, refresh(t, y) takes the state there;
  // factorize(γ′h, β′h²) factorizes S = M̄ + γ′h C̄ + β′h² K̄ at it, the residual form's W_v N;
  // solve(r, x): x = S⁻¹ r; weight(v, out): out = M̄ v at it (W_v). Requires the residual form
  // (set_residual; its weight is not used then) and Z the rates alone (no other first-order
  // states).
  struct NewtonSystem {
    std::function<void(double t, const Eigen::VectorXd& y)> refresh;
    std::function<void(double gh, double bh2)> factorize;
    std::function<void(const Eigen::VectorXd& r, Eigen::VectorXd& x)> solve;
    std::function<void(const Eigen::VectorXd& v, Eigen::VectorXd& out)> weight;
  };
  void set_newton_system(NewtonSystem system);
  // Fixed steps of size h (the last one shortened to t_end) without error control, as structural
  // dynamics codes are used; the tolerances then only stop the Newton iterations. A step whose
  // Newton iterations fail is retried in halves. 0 (the default): error control.
  void set_fixed_step(double h);

  // As Integrator::integrate, with outputs from cubic Hermite interpolation over the step.
  double integrate(const Rhs& f, double t0, double t_end, Eigen::VectorXd& y,
                   const std::vector<double>& touts, const Output& out);

  const Radau5Stats& stats() const;  // cumulative over all integrate calls; nnewton: iterations

 private:
  // Rejected: the right-hand side refused a state (StepRejected, e.g. its kinematics).
  enum class Attempt { Accepted, ErrorTooLarge, SlowNewton, Failed, Rejected };

  bool eval(const Rhs& f, double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy);
  // res_ = f_Z(t, y_new_) − d_new_, or its residual form −R (see set_residual).
  bool newton_residual(const Rhs& f, double t);
  void apply_weight(Eigen::VectorXd& v);  // v's rate part times W_ (residual form)
  void factorize(double h);
  // x = (the Newton matrix)⁻¹ r for a residual of the current form; x = N⁻¹ v, the filter of the
  // error estimate (see error_norm).
  void newton_solve(const Eigen::VectorXd& r, Eigen::VectorXd& x);
  void filter(Eigen::VectorXd& v, Eigen::VectorXd& x);
  void shift_acceleration(double h);                  // a_use_: A for a step of size h
  void state_at(double h, const Eigen::VectorXd& y);  // y_new_, a_new_ from d_new_
  Attempt newton(const Rhs& f, double t, double h, const Eigen::VectorXd& y);
  double error_norm(double h, const Eigen::VectorXd& y);
  size_t emit_outputs(const std::vector<double>& touts, size_t next, double t, double h, double t_new,
                      const Eigen::VectorXd& y, const Output& out);

  int n_, m_, r0_, nz_;
  double alpha_m_, alpha_f_, gamma_, beta_, gamma_d_, beta_d_;
  Eigen::VectorXd rtol_, atol_;
  double hmax_;
  long max_steps_ = Integrator::kMaxSteps;
  double h_initial_ = 0.0, h_last_ = 0.0, h_fixed_ = 0.0;
  StopCondition stop_;
  StepStart step_start_;
  Jacobian jac_;
  Residual residual_;
  Weight weight_;
  NewtonSystem system_;  // set: it replaces J_, N_, W_ and lu_
  // The residual form is used from each Jacobian on until Newton contracts slowly (W_v has
  // drifted); lu_ holds the Newton matrix of factorized_residual_form_.
  bool in_residual_form_ = false, factorized_residual_form_ = false;
  Radau5Stats stats_;
  std::string failure_;
  double theta_ = 0.0, faccon_ = 1.0, slow_factor_ = 0.5;
  int newton_its_ = 0;
  bool have_previous_ = false;  // d_prev_ and h_prev_ hold the step before (error of Z)
  double h_prev_ = 0.0;

  // Work space, allocated once. d_: D at the step start, a_: A there; d_new_, a_new_: at its end.
  Eigen::MatrixXd J_, N_, W_;  // W_: W_v at the Jacobian's state (residual form)
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd d_, a_, a_use_, d_new_, a_new_, d_prev_, dd_, y_new_, fy_, res_, scale_, y_out_, wv_;
};

}  // namespace spacar
