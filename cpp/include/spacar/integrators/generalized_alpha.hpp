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
// A Stepper (stepper.hpp), with the Jacobian ∂f/∂y from the Jacobian callback, reused over steps
// while the simplified Newton iterations converge well, and dense output at the output times by
// cubic Hermite interpolation over the step. The Newton matrix I − γ' h ∂f_Z/∂Z − β' h² ∂f_Z/∂q (size n − m) is
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
#include <memory>
#include <string>

#include "spacar/integrators/stepper.hpp"

namespace spacar {

class GeneralizedAlpha : public Stepper {
 public:
  // n states, of which the first m are positions with rates at rate_offset .. rate_offset + m − 1
  // (m ≤ rate_offset ≤ n − m); rho_inf in [0, 1]. Below kProportionalFrom the tolerances
  // (Stepper::set_tolerances) are tightened for tolerance proportionality (tolerances_set).
  GeneralizedAlpha(int n, int m, int rate_offset, double rho_inf);
  // The stepper of GENERALIZED_ALPHA for a run (the method table, stepper.cpp).
  static std::unique_ptr<Stepper> make(Method method, const StepperSetup& setup);

  // The residual form of the Newton iterations (optional): R = W(y) (D − f_Z(t, y)) for a trial
  // D of Z, with W the identity except in the rates' rows, where it is a matrix W_v (m x m) of
  // the positions (the reduced mass matrix M̄(q) of equations of motion M̄ q̈ = r(q, q̇)). Where
  // the residual costs less than f_Z (no solve with M̄), the iterations use it with the Newton
  // matrix W_v N, W_v taken at the Jacobian's state: the same increments to first order.
  // `weight` gives W_v there, after each call of the Jacobian.
  void set_residual(Residual residual, ResidualWeight weight);
  // A Newton matrix of the caller's own instead of the dense one from the Jacobian (large models,
  // sparse): where the integrator would take a Jacobian, refresh(t, y) takes the state there;
  // factorize(γ′h, β′h²) factorizes S = M̄ + γ′h C̄ + β′h² K̄ at it, the residual form's W_v N;
  // solve(r, x): x = S⁻¹ r; solve_weighted(v, x): x = S⁻¹ M̄ v, M̄ at it (W_v). Requires the residual form
  // (set_residual; its weight is not used then) and Z the rates alone (no other first-order
  // states).
  void set_newton_system(NewtonSystem system);
  // Fixed steps of size h (the last one shortened to t_end) without error control, as structural
  // dynamics codes are used; the tolerances then only stop the Newton iterations. A step whose
  // Newton iterations fail is retried in halves. 0 (the default): error control.
  void set_fixed_step(double h);

 private:
  // Rejected: the right-hand side refused a state (StepRejected, e.g. its kinematics).
  enum class Attempt { Accepted, ErrorTooLarge, SlowNewton, Failed, Rejected };

  // The hooks of Stepper::integrate.
  void check_ready() const override;
  void tolerances_set() override;
  void map_tolerances();
  void begin() override;
  bool start(const Rhs& f, double t0, const Eigen::VectorXd& y) override;
  double first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) override;
  Outcome step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y, Outputs& outputs,
               double& h) override;
  // One attempt of the step and its error (err: 1 under fixed steps).
  Attempt attempt(const Rhs& f, double t, double h_try, const Eigen::VectorXd& y, double& err);

  // res_ = f_Z(t, y_new_) − d_new_, or its residual form −R (see set_residual).
  bool newton_residual(const Rhs& f, double t);
  void apply_weight(Eigen::VectorXd& v);  // v's rate part times W_ (residual form)
  void factorize(double h);
  // x = (the Newton matrix)⁻¹ r for a residual of the current form; x = N⁻¹ v, the filter of the
  // error estimate (see error_norm), with scaled_dx its positions' motion of the coordinates
  // (position_error_).
  void newton_solve(const Eigen::VectorXd& r, Eigen::VectorXd& x);
  void filter(Eigen::VectorXd& v, Eigen::VectorXd& x, Eigen::VectorXd* scaled_dx = nullptr);
  void shift_acceleration(double h);                  // a_use_: A for a step of size h
  void state_at(double h, const Eigen::VectorXd& y);  // y_new_, a_new_ from d_new_
  Attempt newton(const Rhs& f, double t, double h, const Eigen::VectorXd& y);
  double error_norm(double h, const Eigen::VectorXd& y);
  size_t emit_outputs(const std::vector<double>& touts, size_t next, double t, double h, double t_new,
                      const Eigen::VectorXd& y, const Output& out);

  int m_, r0_, nz_;
  double alpha_m_, alpha_f_, gamma_, beta_, gamma_d_, beta_d_;
  double h_fixed_ = 0.0;
  double h_refused_ = 0.0;    // the last step the kinematics or Newton refused (0: none yet)
  double newton_tol_ = 0.02;  // Newton's stop, in units of the tolerance (map_tolerances)
  Eigen::VectorXd rtol_asked_, atol_asked_;  // the tolerances as set, before tolerances_set's map
  std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)> position_error_;  // StepperSetup's
  Eigen::VectorXd dq_, dx_;  // its argument and result
  Residual residual_;
  ResidualWeight weight_;
  NewtonSystem system_;  // set: it replaces J_, N_, W_ and lu_
  // The residual form is used from each Jacobian on until Newton contracts slowly (W_v has
  // drifted); lu_ holds the Newton matrix of factorized_residual_form_.
  bool in_residual_form_ = false, factorized_residual_form_ = false;
  int newton_its_ = 0;
  // The step loop's state (Stepper::integrate's hooks): a rejection before this attempt, whether
  // the Jacobian must be taken (fresh: at the current step start), the step of the factorization
  // in place.
  bool rejected_ = false, need_jacobian_ = true, jacobian_fresh_ = false;
  double h_factorized_ = 0.0;
  bool have_previous_ = false;  // d_prev_ and h_prev_ hold the step before (error of Z)
  double h_prev_ = 0.0;

  // Work space, allocated once. d_: D at the step start, a_: A there; d_new_, a_new_: at its end.
  Eigen::MatrixXd J_, N_, W_;  // W_: W_v at the Jacobian's state (residual form)
  // The rates' rows of W_v ∂f_Z/∂Z and W_v ∂f_Z/∂q (m × nz, m × m), formed once per Jacobian: the
  // residual form's Newton matrix for a step h is then a sum, not a product (factorize).
  Eigen::MatrixXd WJz_, WJq_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd d_, a_, a_use_, d_new_, a_new_, d_prev_, dd_, y_new_, fy_, res_, scale_, newton_scale_, y_out_, wv_;
};

}  // namespace spacar
