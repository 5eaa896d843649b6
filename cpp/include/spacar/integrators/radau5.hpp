// Implicit Runge-Kutta integration for stiff systems: Radau IIA of order 5 (three stages) with
// step-size control, simplified Newton iterations and dense output in the manner of Hairer's
// RADAU5 (E. Hairer, G. Wanner, "Solving Ordinary Differential Equations II", Sec. IV.8).
//
// A Stepper (stepper.hpp): integrate() with dense output at the output times from the
// collocation polynomial. The Jacobian ∂f/∂y comes from the Jacobian callback (dense), evaluated at
// accepted states only and reused over steps while the Newton iterations converge well; the
// factorizations of the Newton matrix are reused while the step size stays put.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <functional>
#include <string>
#include <memory>
#include <vector>

#include "spacar/integrators/stepper.hpp"

namespace spacar {

class Radau5 : public Stepper {
 public:
  explicit Radau5(int n);
  // The stepper of RADAU5 for a run (the method table, stepper.cpp).
  static std::unique_ptr<Stepper> make(Method method, const StepperSetup& setup);

  // The tolerances (Stepper::set_tolerances) are mapped as in Hairer's code,
  // rtol' = 0.1 rtol^(2/3), atol' = atol rtol'/rtol: the error estimate is that of an embedded
  // third-order formula, and this mapping makes the global error about rtol.

  // The Jacobian is kept for the next step when the Newton contraction rate of the step was at
  // most this (Hairer's default 0.001; about 0.1 when the Jacobian is expensive).
  void set_jacobian_reuse(double theta);
  // Second-order structure (Hairer's M1): the first m components are positions whose derivatives
  // are the last m components, f_i(t, y) = y_{n−m+i}, so that the first m rows of J are
  // [0 … 0 I]. The linear systems of the Newton iterations are then reduced to size n − m by
  // eliminating those rows (eight times fewer operations per factorization for m = n/2).
  // Call before integrate(); 0 (the default): no structure assumed.
  void set_second_order(int m);

  // Non-stiffness detection, for a return to an explicit method (bound > 0; 0: off): the spectral
  // radius ρ(J) of every Jacobian taken is computed (its eigenvalues, O(n³) like a
  // factorization, once per Jacobian), and an accepted step of size h with ρ h ≤ bound counts as
  // non-stiff: an explicit method whose stability region reaches out to |hλ| = bound would be
  // stable at this step size. After kNonstiffSteps such steps in a row integrate() stops there
  // (as with the stop condition) and wants_switch() says so.
  void set_nonstiffness_detection(double bound);
  double spectral_radius() const;      // ρ(J) of the last Jacobian (0 if not detecting)
  static constexpr int kNonstiffSteps = 15;

 private:
  enum class Attempt { Accepted, ErrorTooLarge, SlowNewton, Failed };

  // The hooks of Stepper::integrate.
  void check_ready() const override;
  void begin() override;
  bool start(const Rhs& f, double t0, const Eigen::VectorXd& y) override;
  double first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) override;
  Outcome step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y, Outputs& outputs,
               double& h) override;
  bool switch_after_step(double t, double t_end, double h) override;
  void tolerances_set() override;

  double initial_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y);
  void factorize(double h);
  // x = (σ − J)⁻¹ r with the factorization of the real shift σ = γ/h (x may alias nothing).
  void solve_real(const Eigen::VectorXd& r, Eigen::VectorXd& x);
  // r ← ((α + iβ)/h − J)⁻¹ r with the complex factorization.
  void solve_complex(Eigen::VectorXcd& r);
  void starting_values(double h);
  Attempt newton(const Rhs& f, double t, double h, const Eigen::VectorXd& y);
  bool estimate_error(const Rhs& f, double t, double h, const Eigen::VectorXd& y, bool refine);
  Attempt attempt_step(const Rhs& f, double t, double h, const Eigen::VectorXd& y, bool refine);
  void build_polynomial();
  void polynomial_value(double s);  // y_out_ = u(t_new + s h_old), s in [-1, 0]
  size_t emit_outputs(const std::vector<double>& touts, size_t next, double t_new, const Output& out);

  int m_ = 0;                     // second-order positions (set_second_order)
  double fnewt_ = 0.03;           // Newton stopping criterion (scaled norm of the increment)
  double theta_reuse_ = 0.001;
  double nonstiff_bound_ = 0.0, rho_ = 0.0;
  int nonstiff_steps_ = 0;
  Eigen::EigenSolver<Eigen::MatrixXd> eigen_;

  // The step loop's state (Stepper::integrate's hooks): the first step, a rejection before this
  // attempt, whether the Jacobian must be taken (fresh: at the current step start), the step of
  // the factorizations in place, the last accepted step and its error (the predictive
  // controller), and the steps accepted in this integrate() call.
  bool first_ = true, rejected_ = false, need_jacobian_ = true, jacobian_fresh_ = false;
  double h_factorized_ = 0.0, h_acc_ = 0.0, err_acc_ = 0.0;
  long accepted_here_ = 0;

  // Newton state carried between steps (with Stepper's theta_ and faccon_); the last error norm.
  double err_ = 0.0;
  int newton_its_ = 0;
  bool have_polynomial_ = false;  // a previous step's collocation polynomial predicts Z
  double h_old_ = 0.0, t_new_ = 0.0;

  // Work space, allocated once.
  // E1_, E2_: the reduced Newton matrices (size n − m), overwritten by their LU factors;
  // G1_, G2_: the columns of the rates in
  // the remaining rows, σ S − J[m:n, n−m:n], which carry the eliminated rows into them.
  Eigen::MatrixXd J_, E1_, G1_;
  Eigen::MatrixXcd E2_, G2_;
  double sigma1_ = 0.0;
  std::complex<double> sigma2_;
  Eigen::VectorXd rr_;
  Eigen::VectorXcd cr_;
  std::vector<int> piv_real_, piv_complex_;  // row interchanges of the LU factors in E1_, E2_
  Eigen::VectorXd f0_, scale_, newton_scale_, y_stage_, y_new_, y_out_, err_v_, dz_, tmp_;
  Eigen::VectorXcd ctmp_;
  Eigen::VectorXd z_[3], w_[3], fz_[3], poly_[3];
};

}  // namespace spacar
