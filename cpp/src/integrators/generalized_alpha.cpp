// Generalized-α with local-error step control (see generalized_alpha.hpp).
#include "spacar/integrators/generalized_alpha.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "spacar/errors.hpp"

namespace spacar {
namespace {

// Newton stops when the predicted remaining error of the states is below this fraction of the
// tolerance (the scaled norm in which the local error must stay below 1).
constexpr double kNewtonTolerance = 0.02;
// The residual form is left when Newton's contraction factor exceeds this: W_v may have moved from
// M̄ by about as much (a relative change of the mass matrix), which costs iterations where the
// form with the exact M̄ still converges in two.
constexpr double kResidualDrift = 1e-3;
// Tolerance proportionality: a relative tolerance r below this is tightened to r √(r / it). With
// the local error held to τ per step, a second-order method's global error grows as τ^(2/3) over
// a smooth motion (measured on the damped cantilevers of benchmarks/error_control.py: 3.2 EPSINT
// at 1e-6, 7 at 1e-7, 16 at 1e-8); with τ = r^(3/2) / √(1e-5) it follows r (about 1.5 r there).
// Above it, and wherever unresolved modes set the step (the undamped beams: 0.2 r), the
// tolerance stays as asked. Radau5 maps its tolerances for the same reason (Hairer's r^(2/3)).
constexpr double kProportionalFrom = 1e-5;
// ... but not below this (or the tolerance asked for, if smaller): Newton's stop, 2 % of it,
// would sink into round-off.
constexpr double kTightest = 1e-12;
// Newton stops at kNewtonTolerance of the tolerance, but at no looser a relative tolerance than
// this one's: at EPSINT 0.1 the iterates it left unconverged carried the unresolved modes of a
// 128-element cantilever into states the kinematics refused, step after step (18 533 steps, 10 882
// refused, 14 s; 106 steps at EPSINT 0.01).
constexpr double kLoosestNewton = 0.01;
// After a step refused by the kinematics or Newton, later steps stay below this fraction of it,
// a bound that grows by kRefusedRecovery per step taken.
constexpr double kRefusedFraction = 0.5;
constexpr double kRefusedRecovery = 1.2;
// An accepted step is kept (and its factorization with it) unless the estimate lets it grow by
// more than this factor (Hairer's RADAU5 keeps it for growth up to 1.2 too, see step()).
constexpr double kGrowFrom = 1.2;

}  // namespace

GeneralizedAlpha::GeneralizedAlpha(int n, int m, int rate_offset, double rho_inf)
    : Stepper("GeneralizedAlpha", n), m_(m), r0_(rate_offset), nz_(n - m) {
  if (n < 1 || m < 1 || rate_offset < m || rate_offset + m > n)
    throw std::invalid_argument("GeneralizedAlpha: needs m >= 1 positions with their rates among the n states");
  if (!(rho_inf >= 0.0 && rho_inf <= 1.0))
    throw std::invalid_argument("GeneralizedAlpha: the spectral radius rho_inf must be in [0, 1]");
  // Chung & Hulbert's parameters: second order, ρ∞ at infinite frequency, the least low-frequency
  // dissipation for that ρ∞.
  alpha_m_ = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
  alpha_f_ = rho_inf / (rho_inf + 1.0);
  gamma_ = 0.5 - alpha_m_ + alpha_f_;
  beta_ = 0.25 * (1.0 - alpha_m_ + alpha_f_) * (1.0 - alpha_m_ + alpha_f_);
  // γ′, β′: the derivatives of Z⁺ (per h) and q⁺ (per h²) with respect to D⁺, through A⁺.
  const double c = (1.0 - alpha_f_) / (1.0 - alpha_m_);
  gamma_d_ = gamma_ * c;
  beta_d_ = beta_ * c;
  // J_, N_ and lu_ (dense, n² and nz²) are sized at the first Jacobian: a Newton system
  // (set_newton_system) never needs them.
  for (Eigen::VectorXd* v : {&d_, &a_, &a_use_, &d_new_, &a_new_, &d_prev_, &dd_, &res_}) v->setZero(nz_);
  for (Eigen::VectorXd* v : {&y_new_, &fy_, &scale_, &newton_scale_, &y_out_}) v->setZero(n);
  wv_.setZero(m);
}

std::unique_ptr<Stepper> GeneralizedAlpha::make(Method, const StepperSetup& setup) {
  if (setup.positions == 0) throw InputError("method generalized_alpha: the model has no degrees of freedom to integrate");
  auto stepper = std::make_unique<GeneralizedAlpha>(setup.n, setup.positions, setup.rate_offset, setup.rho_inf);
  stepper->set_jacobian(setup.jacobian);
  if (setup.residual) stepper->set_residual(setup.residual, setup.weight);
  if (setup.newton.refresh) stepper->set_newton_system(setup.newton);
  stepper->set_fixed_step(setup.fixed_step);
  stepper->position_error_ = setup.position_error;
  return stepper;
}

void GeneralizedAlpha::set_fixed_step(double h) {
  if (!(h >= 0) || !std::isfinite(h)) throw std::invalid_argument("GeneralizedAlpha: the fixed step must be finite and >= 0");
  h_fixed_ = h;
  map_tolerances();
}

void GeneralizedAlpha::tolerances_set() {
  rtol_asked_ = rtol_;
  atol_asked_ = atol_;
  map_tolerances();
}

// At fixed steps the tolerances only stop Newton's iterations: they stay as asked.
void GeneralizedAlpha::map_tolerances() {
  if (rtol_asked_.size() != n_) return;  // not set yet (set_fixed_step before set_tolerances)
  rtol_ = rtol_asked_;
  atol_ = atol_asked_;
  if (h_fixed_ == 0) {
    for (int i = 0; i < n_; ++i) {
      if (!(rtol_[i] > 0 && rtol_[i] < kProportionalFrom)) continue;
      const double mapped = std::max(rtol_[i] * std::sqrt(rtol_[i] / kProportionalFrom), std::min(rtol_[i], kTightest));
      atol_[i] *= mapped / rtol_[i];
      rtol_[i] = mapped;
    }
  }
  // Newton's stop, in units of the tolerance: above round-off (as Radau5's) and below kLoosestNewton.
  double rmin = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n_; ++i)
    if (rtol_[i] > 0) rmin = std::min(rmin, rtol_[i]);
  const double rmax = std::max(rtol_.maxCoeff(), kRound);
  newton_tol_ = kNewtonTolerance * std::min(1.0, kLoosestNewton / rmax);
  if (std::isfinite(rmin)) newton_tol_ = std::max(newton_tol_, 10.0 * kRound / rmin);
}

void GeneralizedAlpha::set_newton_system(NewtonSystem system) {
  if (nz_ != m_) throw std::invalid_argument("GeneralizedAlpha: a Newton system needs the rates as the only other states");
  if (!system.refresh || !system.factorize || !system.solve || !system.solve_weighted)
    throw std::invalid_argument("GeneralizedAlpha: a Newton system needs refresh, factorize, solve and solve_weighted");
  system_ = std::move(system);
}
void GeneralizedAlpha::set_residual(Residual residual, ResidualWeight weight) {
  residual_ = std::move(residual);
  weight_ = std::move(weight);
}

bool GeneralizedAlpha::newton_residual(const Rhs& f, double t) {
  if (!in_residual_form_) {
    if (!eval(f, t, y_new_, fy_)) return false;
    res_ = fy_.tail(nz_) - d_new_;
    return true;
  }
  ++stats_.nfev;
  ++stats_.nresidual;
  residual_(t, y_new_, d_new_, res_);
  if (res_.size() != nz_)
    throw std::invalid_argument("GeneralizedAlpha: the residual has " + std::to_string(res_.size()) + " values for " +
                                std::to_string(nz_) + " states");
  if (!res_.allFinite()) {
    failure_ = "non-finite residual";
    return false;
  }
  res_ = -res_;
  return true;
}

void GeneralizedAlpha::apply_weight(Eigen::VectorXd& v) {
  if (!in_residual_form_) return;
  const int r = r0_ - m_;
  wv_.noalias() = W_ * v.segment(r, m_);
  v.segment(r, m_) = wv_;
}

// N = I − γ′ h ∂f_Z/∂Z − β′ h² ∂f_Z/∂q: the derivative of the residual D⁺ − f_Z(q⁺, Z⁺) with
// respect to D⁺; in the residual form its rate rows times W_v.
void GeneralizedAlpha::factorize(double h) {
  const double gh = gamma_d_ * h, bh2 = beta_d_ * h * h;
  factorized_residual_form_ = in_residual_form_;
  ++stats_.ndec;
  if (system_.factorize) {  // S = W_v N, the same in both forms (newton_solve weighs the other)
    system_.factorize(gh, bh2);
    return;
  }
  const int r = r0_ - m_;
  N_ = -gh * J_.bottomRightCorner(nz_, nz_);
  N_.diagonal().array() += 1.0;
  N_.middleCols(r, m_) -= bh2 * J_.bottomLeftCorner(nz_, m_);
  if (in_residual_form_) {  // the rates' rows W_v (I − γ′h ∂f/∂Z − β′h² ∂f/∂q) from the products kept
    N_.middleRows(r, m_) = -gh * WJz_;
    N_.block(r, r, m_, m_) += W_ - bh2 * WJq_;
  }
  lu_.compute(N_);
}

void GeneralizedAlpha::newton_solve(const Eigen::VectorXd& r, Eigen::VectorXd& x) {
  if (!system_.solve) {
    x = lu_.solve(r);
    return;
  }
  // The residual form's r is W_v (D − f): S⁻¹ r; the other form's f − D: N⁻¹ = S⁻¹ W_v.
  if (in_residual_form_) {
    system_.solve(r, x);
    return;
  }
  system_.solve_weighted(r, x, nullptr);
}

void GeneralizedAlpha::filter(Eigen::VectorXd& v, Eigen::VectorXd& x, Eigen::VectorXd* scaled_dx) {
  if (system_.solve) {
    system_.solve_weighted(v, x, scaled_dx);
    return;
  }
  apply_weight(v);  // N⁻¹ = (W_v N)⁻¹ W_v in the residual form
  x = lu_.solve(v);
  if (scaled_dx) {
    dq_ = x.segment(r0_ - m_, m_);
    position_error_(dq_, *scaled_dx);
  }
}

void GeneralizedAlpha::state_at(double h, const Eigen::VectorXd& y) {
  const double c = 1.0 / (1.0 - alpha_m_);
  a_new_ = c * ((1.0 - alpha_f_) * d_new_ + alpha_f_ * d_ - alpha_m_ * a_use_);
  y_new_.tail(nz_) = y.tail(nz_) + h * ((1.0 - gamma_) * a_use_ + gamma_ * a_new_);
  const int r = r0_ - m_;  // the rates' place in Z
  y_new_.head(m_) = y.head(m_) + h * y.segment(r0_, m_) +
                    (h * h) * ((0.5 - beta_) * a_use_.segment(r, m_) + beta_ * a_new_.segment(r, m_));
}

// A approximates D at t + (αm − αf) h of the step that made it (Arnold & Brüls): after a change of
// the step size it is moved to the new step's shift along the last divided difference of D, or
// the method drops to first order wherever the step changes (ρ∞ < 1; at ρ∞ = 1, A = D).
void GeneralizedAlpha::shift_acceleration(double h) {
  a_use_ = a_;
  if (have_previous_ && h != h_prev_)
    a_use_ += ((alpha_m_ - alpha_f_) * (h - h_prev_) / h_prev_) * (d_ - d_prev_);
}

// Simplified Newton iterations for D⁺ from the predictor D⁺ = D (the Jacobian and the
// factorization for h in place), with the convergence monitoring of Hairer's RADAU5. On success
// y_new_, a_new_ and d_new_ hold the end of the step: D⁺ is the converged iterate, not a new
// evaluation of f (one right-hand side per iteration, none more per step).
GeneralizedAlpha::Attempt GeneralizedAlpha::newton(const Rhs& f, double t, double h, const Eigen::VectorXd& y) {
  const double gh = gamma_d_ * h, bh2 = beta_d_ * h * h;
  const int r = r0_ - m_;
  scale_ = atol_.array() + rtol_.array() * y.array().abs();
  newton_divisors(scale_, newton_tol_, newton_scale_);
  shift_acceleration(h);
  d_new_ = d_;
  faccon_ = std::pow(std::max(faccon_, kRound), 0.8);
  theta_ = 0.0;  // converged in one iteration: the Jacobian serves well
  double dn_old = 0.0, thq_old = 0.0;
  for (int it = 1; it <= kMaxNewton; ++it) {
    ++stats_.nnewton;
    newton_its_ = it;
    state_at(h, y);
    if (!newton_residual(f, t + h)) return Attempt::Failed;
    newton_solve(res_, dd_);
    // The increment's effect on the states, in units of the tolerance.
    const double sq = (bh2 * dd_.segment(r, m_).array() / newton_scale_.head(m_).array()).square().sum() +
                      (gh * dd_.array() / newton_scale_.tail(nz_).array()).square().sum();
    const double dn = std::sqrt(sq / n_);
    if (!std::isfinite(dn)) {
      failure_ = "singular Newton matrix";
      return Attempt::Failed;
    }
    if (it > 1) {
      const Contraction c = newton_contraction(it, dn, dn_old, thq_old, newton_tol_);
      if (c == Contraction::Diverges) return Attempt::Failed;
      if (c == Contraction::TooSlow) return Attempt::SlowNewton;
    }
    dn_old = std::max(dn, kRound);
    d_new_ += dd_;
    if (faccon_ * dn <= newton_tol_) {
      state_at(h, y);
      return Attempt::Accepted;
    }
  }
  failure_ = "Newton iterations did not converge";
  return Attempt::Failed;
}

// Scaled RMS of the local error estimate over the positions and the first-order states other
// than the rates (see the header), filtered through the Newton matrix as in Hairer's RADAU5: a
// mode of frequency ω is weighted by 1 / (1 + β' (ω h)²), so that the modes the step does not
// resolve count with their amplitude, not with their acceleration times h². With position_error_
// the positions' estimate is also measured in the nodal coordinates, and the larger of the two
// norms sets the step: a flexible beam's DOFs are its elements' deformations, whose errors its
// tip adds up (issue 36: 71 EPSINT at 128 elements on the DOFs alone), while the deformations
// themselves (a closed loop's, the stresses') need the DOFs' own norm.
double GeneralizedAlpha::error_norm(double h, const Eigen::VectorXd& y) {
  const int r = r0_ - m_;
  scale_ = atol_.array() + rtol_.array() * y.array().abs().max(y_new_.array().abs());
  // res_ (in the layout of Z): the positions' estimates in the rates' places, the others' in theirs.
  res_.setZero();
  for (int i = 0; i < m_; ++i)
    res_[r + i] = h * h * ((0.5 - beta_) * a_use_[r + i] + beta_ * a_new_[r + i] - d_[r + i] / 3.0 - d_new_[r + i] / 6.0);
  if (have_previous_) {
    const double k = h * h * h / 6.0 / (h + h_prev_);
    for (int j = 0; j < nz_; ++j)
      if (j < r || j >= r + m_) res_[j] = k * ((d_new_[j] - d_[j]) / h - (d_[j] - d_prev_[j]) / h_prev_);
  }
  filter(res_, dd_, position_error_ ? &dx_ : nullptr);
  double sum = 0.0;
  for (int j = 0; j < nz_; ++j) {
    const double sc = j >= r && j < r + m_ ? scale_[j - r] : scale_[m_ + j];
    sum += (dd_[j] / sc) * (dd_[j] / sc);
  }
  double err = std::sqrt(sum / nz_);  // nz_ = m positions + the others, rates left out
  if (position_error_) {  // and the positions' error in the coordinates, relative to (10⁻³ + |x|)
    const double eps = rtol_[0];
    double coords = 0.0;
    for (Eigen::Index c = 0; c < dx_.size(); ++c) coords += (dx_[c] / eps) * (dx_[c] / eps);
    if (dx_.size()) err = std::max(err, std::sqrt(coords / static_cast<double>(dx_.size())));
  }
  return std::max(err, kMinError);
}

// Cubic Hermite interpolation over the step [t, t + h] from the values and derivatives at its ends.
size_t GeneralizedAlpha::emit_outputs(const std::vector<double>& touts, size_t next, double t, double h,
                                      double t_new, const Eigen::VectorXd& y, const Output& out) {
  for (; next < touts.size() && touts[next] <= t_new; ++next) {
    if (touts[next] == t_new) {
      out(t_new, y_new_);
      continue;
    }
    const double s = (touts[next] - t) / h;
    const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h01 = s * s * (3 - 2 * s);
    const double h10 = s * (1 - s) * (1 - s) * h, h11 = s * s * (s - 1) * h;
    y_out_ = h00 * y + h01 * y_new_;
    y_out_.head(m_) += h10 * y.segment(r0_, m_) + h11 * y_new_.segment(r0_, m_);
    y_out_.tail(nz_) += h10 * d_ + h11 * d_new_;
    out(touts[next], y_out_);
  }
  return next;
}

void GeneralizedAlpha::check_ready() const {
  if (!jac_ && !system_.refresh) throw std::invalid_argument("GeneralizedAlpha: no Jacobian callback set");
  if (system_.refresh && !residual_) throw std::invalid_argument("GeneralizedAlpha: a Newton system needs the residual form");
}

void GeneralizedAlpha::begin() {
  rejected_ = jacobian_fresh_ = false;
  need_jacobian_ = true;
  h_factorized_ = 0.0;
  h_refused_ = 0.0;
  faccon_ = 1.0;
}

bool GeneralizedAlpha::start(const Rhs& f, double t0, const Eigen::VectorXd& y) {
  if (!eval(f, t0, y, fy_)) return false;
  d_ = fy_.tail(nz_);
  a_ = d_;  // A = D at the start (Arnold & Brüls): second order from the first step
  have_previous_ = false;
  return true;
}

double GeneralizedAlpha::first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) {
  double h = h_fixed_ > 0 ? h_fixed_ : h_initial_;
  if (!(h > 0)) {
    // Hairer's starting step for a method of order 2.
    scale_ = atol_.array() + rtol_.array() * y.array().abs();
    const double d0 = std::sqrt((y.array() / scale_.array()).square().mean());
    const double d1 = std::sqrt((fy_.array() / scale_.array()).square().mean());
    const double h0 = std::min((d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1, t_end - t0);
    double dmax = d1;
    y_new_ = y + h0 * fy_;
    try {
      if (eval(f, t0 + h0, y_new_, y_out_))
        dmax = std::max(d1, std::sqrt(((y_out_ - fy_).array() / scale_.array()).square().mean()) / h0);
    } catch (const StepRejected&) {
    }
    const double h1 = dmax <= 1e-15 ? std::max(1e-6, 1e-3 * h0) : std::pow(0.01 / dmax, 1.0 / 3.0);
    h = std::min(100.0 * h0, h1);
  }
  return std::min({h, hmax_, t_end - t0});
}

GeneralizedAlpha::Attempt GeneralizedAlpha::attempt(const Rhs& f, double t, double h_try, const Eigen::VectorXd& y,
                                                    double& err) {
  if (need_jacobian_ && system_.refresh) {
    ++stats_.njev;
    system_.refresh(t, y);
    need_jacobian_ = false;
    jacobian_fresh_ = true;
    h_factorized_ = 0.0;
    in_residual_form_ = true;
  } else if (need_jacobian_) {
    ++stats_.njev;
    if (J_.rows() != n_) {
      J_.setZero(n_, n_);
      N_.setZero(nz_, nz_);
      lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(nz_);
    }
    jac_(t, y, J_);
    if (J_.rows() != n_ || J_.cols() != n_) throw std::invalid_argument("GeneralizedAlpha: the Jacobian has the wrong size");
    if (!J_.allFinite()) throw IntegrationError("GeneralizedAlpha: non-finite Jacobian at " + describe_step(t, h_try));
    if (residual_) {
      weight_(W_);
      if (W_.rows() != m_ || W_.cols() != m_ || !W_.allFinite())
        throw IntegrationError("GeneralizedAlpha: the residual's weight is not a finite " + std::to_string(m_) + " x " +
                               std::to_string(m_) + " matrix at " + describe_step(t, h_try));
      const int r = r0_ - m_;
      WJz_.noalias() = W_ * J_.bottomRightCorner(nz_, nz_).middleRows(r, m_);
      WJq_.noalias() = W_ * J_.bottomLeftCorner(nz_, m_).middleRows(r, m_);
    }
    need_jacobian_ = false;
    jacobian_fresh_ = true;
    h_factorized_ = 0.0;
    in_residual_form_ = static_cast<bool>(residual_);  // W_v is fresh
  }
  if (h_try != h_factorized_ || in_residual_form_ != factorized_residual_form_) {
    factorize(h_try);
    h_factorized_ = h_try;
  }
  Attempt result = newton(f, t, h_try, y);
  if (result == Attempt::Accepted && h_fixed_ > 0) {
    err = 1.0;  // no control: keep the step
  } else if (result == Attempt::Accepted) {
    err = error_norm(h_try, y);
    if (!std::isfinite(err)) {
      failure_ = "non-finite error estimate";
      result = Attempt::Failed;
    } else if (err >= 1.0) {
      failure_ = "local error above tolerance";
      result = Attempt::ErrorTooLarge;
    }
  }
  return result;
}

Stepper::Outcome GeneralizedAlpha::step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y,
                                        Outputs& outputs, double& h) {
  Attempt result = Attempt::Failed;
  double err = 0.0;
  try {
    result = attempt(f, t, h_try, y, err);
  } catch (const StepRejected& e) {
    failure_ = e.what();
    result = Attempt::Rejected;
  }
  // The local error behaves as h³.
  const double quot = std::clamp(std::cbrt(err) / kStepSafety, 0.2, 5.0);
  if (result != Attempt::Accepted) {
    if (in_residual_form_ && (result == Attempt::SlowNewton || result == Attempt::Failed) &&
        failure_ != "non-finite residual") {
      // W_v may have drifted from M̄ (the mechanism has moved since the Jacobian): the same
      // step again in the form with the exact M̄, from the same anchor.
      in_residual_form_ = false;
      return Outcome::Retry;
    }
    rejected_ = true;
    // The step size is the likely cause where the kinematics refused the state, or Newton failed
    // with a fresh Jacobian (with an old one a new Jacobian is the remedy, below).
    if (result == Attempt::Rejected || (result != Attempt::ErrorTooLarge && jacobian_fresh_)) h_refused_ = h_try;
    if (result == Attempt::ErrorTooLarge) h = h_try / quot;
    else if (result == Attempt::SlowNewton) h = h_try * slow_factor_;
    else h = 0.5 * h_try;
    // A Jacobian from an earlier state may be why Newton failed; not when the step converged
    // (its error was too large) or the right-hand side refused the state (the kinematics).
    need_jacobian_ = !jacobian_fresh_ && result != Attempt::ErrorTooLarge && result != Attempt::Rejected;
    return Outcome::Rejected;
  }
  double h_new = std::min(h_try / quot, hmax_);
  if (rejected_) h_new = std::min(h_new, h_try);
  if (h_refused_ > 0) {
    // A step the kinematics or Newton refused (not the error estimate): grow back towards it
    // slowly. Back at once to the step the error allows, a 128-element cantilever at EPSINT 0.1
    // was refused about six times for every two steps taken.
    h_new = std::min(h_new, std::max(h_try, kRefusedFraction * h_refused_));
    h_refused_ *= kRefusedRecovery;
  }
  if (h_fixed_ > 0) h_new = std::min(2.0 * h_try, h_fixed_);  // back to the fixed step after halvings
  outputs.next = emit_outputs(outputs.touts, outputs.next, t, h_try, t_new, y, outputs.out);
  d_prev_ = d_;
  h_prev_ = h_try;
  have_previous_ = true;
  d_ = d_new_;
  a_ = a_new_;
  y = y_new_;
  rejected_ = jacobian_fresh_ = false;
  // A Jacobian is a linearization: keep it while Newton contracts. In the residual form a
  // contraction factor above kResidualDrift may be the drift of W_v alone: the form with the
  // exact M̄ from here until the next Jacobian.
  if (in_residual_form_ && theta_ > kResidualDrift) in_residual_form_ = false;
  need_jacobian_ = theta_ > 0.1;
  // Keep the step, and with it the factorization, unless it may grow by more than kGrowFrom. An
  // accepted step is not shrunk (unless a new Jacobian is due): a structure's unresolved modes
  // make the estimate scatter from step to step (0.4 to 0.9 at the same step on the 64-element
  // cantilever at EPSINT 1e-5), and shrinking on its high values refactorized the Newton matrix
  // at a third of the steps, for changes the next estimates undid (520 factorizations in 1393
  // steps; 147 in 1368 kept, 22 % less time). A step whose estimate exceeds the tolerance is
  // still refused and shrunk.
  if (!need_jacobian_ && h_new <= kGrowFrom * h_try) h_new = h_try;
  h = h_new;
  return Outcome::Accepted;
}

}  // namespace spacar
