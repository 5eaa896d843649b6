// Radau IIA of order 5 (see radau5.hpp). The stage equations Z - h (A ⊗ I) F(Z) = 0 for the stage
// increments Z = (z1, z2, z3) are solved by simplified Newton iterations with the Jacobian J of the
// step start. Multiplied by (h A)^-1 and transformed with the eigenvectors T of A^-1
// (T^-1 A^-1 T = Λ: one real eigenvalue γ and a complex pair α ± iβ) the Newton system falls
// apart into one real system (γ/h - J) and one complex system ((α + iβ)/h - J) of size n.
// Step-size control: Hairer's error estimate (the embedded third-order formula filtered by
// (γ/h - J)^-1, which keeps it bounded for stiff components) with the predictive (Gustafsson)
// controller; the Newton iterations also reject steps whose convergence is too slow.
#include "spacar/integrators/radau5.hpp"

#include "spacar/integrators/integrator.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace spacar {
namespace {

// Radau IIA nodes, the transformation T, its inverse and Λ = T^-1 A^-1 T.
struct Tableau {
  double c[3];
  Eigen::Matrix3d T, TI, L;
  // Error estimate: y_embedded - y_new = (h/γ) f(t, y) + Σ e_i z_i with e = d/γ below, i.e.
  // err = (γ/h - J)^-1 (f(t, y) + Σ d_i z_i / h) (Hairer & Wanner IV.8, (8.19)-(8.20)).
  double d[3];
};

Tableau make_tableau() {
  Tableau tb;
  const double s6 = std::sqrt(6.0);
  tb.c[0] = (4.0 - s6) / 10.0;
  tb.c[1] = (4.0 + s6) / 10.0;
  tb.c[2] = 1.0;
  Eigen::Matrix3d A;
  A << (88.0 - 7.0 * s6) / 360.0, (296.0 - 169.0 * s6) / 1800.0, (-2.0 + 3.0 * s6) / 225.0,
      (296.0 + 169.0 * s6) / 1800.0, (88.0 + 7.0 * s6) / 360.0, (-2.0 - 3.0 * s6) / 225.0,
      (16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0;
  const Eigen::Matrix3d Ainv = A.inverse();
  const Eigen::EigenSolver<Eigen::Matrix3d> es(Ainv);
  int real = 0, complex = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(es.eigenvalues()[i].imag()) < 1e-12) real = i;
    else if (es.eigenvalues()[i].imag() > 0) complex = i;
  }
  tb.T.col(0) = es.eigenvectors().col(real).real();
  tb.T.col(1) = es.eigenvectors().col(complex).real();
  tb.T.col(2) = es.eigenvectors().col(complex).imag();
  tb.TI = tb.T.inverse();
  tb.L = tb.TI * Ainv * tb.T;  // [[γ, 0, 0], [0, α, β], [0, -β, α]] up to round-off
  tb.d[0] = -(13.0 + 7.0 * s6) / 3.0;
  tb.d[1] = (-13.0 + 7.0 * s6) / 3.0;
  tb.d[2] = -1.0 / 3.0;
  return tb;
}

const Tableau& tableau() {
  static const Tableau tb = make_tableau();
  return tb;
}

double scaled_rms(const Eigen::VectorXd& v, const Eigen::VectorXd& scale) {
  return std::sqrt((v.array() / scale.array()).square().sum() / static_cast<double>(v.size()));
}

}  // namespace

Radau5::Radau5(int n) : Stepper("Radau5", n) {
  if (n < 1) throw std::invalid_argument("Radau5: the system needs at least one state");
  set_tolerances(Eigen::VectorXd::Constant(n, 1e-6), Eigen::VectorXd::Constant(n, 1e-6));
  J_.setZero(n, n);
  set_second_order(0);
  for (Eigen::VectorXd* v : {&f0_, &scale_, &newton_scale_, &y_stage_, &y_new_, &y_out_, &err_v_, &dz_, &tmp_}) v->setZero(n);
  ctmp_.setZero(n);
  for (int i = 0; i < 3; ++i)
    for (Eigen::VectorXd* v : {&z_[i], &w_[i], &fz_[i], &poly_[i]}) v->setZero(n);
}

std::unique_ptr<Stepper> Radau5::make(Method, const StepperSetup& setup) {
  auto stepper = std::make_unique<Radau5>(setup.n);
  stepper->set_jacobian(setup.jacobian);
  // Y = (q, y, q̇): q̇ = dq/dt, the last components (not with quadrature states after them).
  if (setup.rate_offset + setup.positions == setup.n) stepper->set_second_order(setup.positions);
  stepper->set_jacobian_reuse(setup.jacobian_reuse);
  // AUTO: back to DOP853 when its stability bound (|hλ| ≤ 6.1) would allow explicit_gain times
  // Radau's steps.
  if (setup.auto_switch)
    stepper->set_nonstiffness_detection(Integrator::stiffness_bound(Method::DOP853) / setup.explicit_gain);
  return stepper;
}

// Hairer's mapping of the tolerances and his default stopping criterion of the Newton iterations.
void Radau5::tolerances_set() {
  double rmin = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n_; ++i) {
    if (rtol_[i] > 0) {
      const double r = 0.1 * std::pow(rtol_[i], 2.0 / 3.0);
      atol_[i] = atol_[i] * r / rtol_[i];
      rtol_[i] = r;
      rmin = std::min(rmin, r);
    }
  }
  const double tol = std::isfinite(rmin) ? rmin : 1e-6;
  fnewt_ = std::max(10.0 * kRound / tol, std::min(0.03, std::sqrt(tol)));
}

void Radau5::set_second_order(int m) {
  if (m < 0 || 2 * m > n_) throw std::invalid_argument("Radau5: the second-order positions must be at most half the states");
  m_ = m;
  const int r = n_ - m;
  E1_.setZero(r, r);
  E2_.setZero(r, r);
  G1_.setZero(r, m);
  G2_.setZero(r, m);
  rr_.setZero(r);
  cr_.setZero(r);
  piv_real_.assign(r, 0);
  piv_complex_.assign(r, 0);
}

void Radau5::set_jacobian_reuse(double theta) {
  if (!(theta > 0 && theta < 1)) throw std::invalid_argument("Radau5: the reuse threshold must be in (0, 1)");
  theta_reuse_ = theta;
}

void Radau5::set_nonstiffness_detection(double bound) {
  if (!(bound >= 0) || !std::isfinite(bound))
    throw std::invalid_argument("Radau5: the non-stiffness bound must be finite and >= 0");
  nonstiff_bound_ = bound;
}
double Radau5::spectral_radius() const { return rho_; }
// Hairer's starting step estimate (as Integrator's) for a method of order 5; uses f0_.
double Radau5::initial_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) {
  const double span = std::min(hmax_, t_end - t0);
  scale_ = atol_.array() + rtol_.array() * y.array().abs();
  const double d0 = scaled_rms(y, scale_), d1 = scaled_rms(f0_, scale_);
  const double h0 = std::min((d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1, span);
  y_stage_ = y + h0 * f0_;
  try {
    if (!eval(f, t0 + h0, y_stage_, tmp_)) return h0;
  } catch (const StepRejected&) {
    return h0;
  }
  const double d2 = scaled_rms(tmp_ - f0_, scale_) / h0;
  const double dmax = std::max(d1, d2);
  const double h1 = dmax <= 1e-15 ? std::max(1e-6, 1e-3 * h0) : std::pow(0.01 / dmax, 1.0 / 6.0);
  return std::min({100.0 * h0, h1, span});
}

// The real matrix γ/h - J and the complex one (α + iβ)/h - J, factorized; with second-order
// structure (m_ > 0) reduced to the unknowns (a, b) = (y[0:m], y[m:n−m]). The rows i < m read
// σ a_i − c_i = r_i, so c = σ a − r[0:m]; put into the rows m.. (σ − J)[m:n, :] x = r[m:n]:
//   [−J[m:n, 0:m] + σ G | (σ − J)[m:n, m:n−m]] (a, b) = r[m:n] + G r[0:m],  G = (σ − J)[m:n, n−m:n].
namespace {
template <class Scalar, class Matrix>
void reduced_matrix(const Eigen::MatrixXd& J, int m, Scalar sigma, Matrix& E, Matrix& G) {
  const int n = static_cast<int>(J.rows()), r = n - m;
  G = -J.block(m, n - m, r, m).template cast<Scalar>();
  G.bottomRows(m).diagonal().array() += sigma;
  E.leftCols(m) = -J.block(m, 0, r, m).template cast<Scalar>() + sigma * G;
  E.rightCols(r - m) = -J.block(m, m, r, r - m).template cast<Scalar>();
  E.topRightCorner(r - m, r - m).diagonal().array() += sigma;
}

// LU factorization with partial pivoting in place (A = P L U, piv the row interchanges), and the
// solve with it. The Newton matrices are small (the DOFs of a structure, tens): a plain
// column-oriented elimination costs less than a general blocked LU's dispatch, and the pivot
// search on |re| + |im| (LAPACK's CABS1) avoids a hypot per complex entry.
double magnitude(double v) { return std::abs(v); }
double magnitude(const std::complex<double>& v) { return std::abs(v.real()) + std::abs(v.imag()); }

template <class Matrix>
void lu_factor(Matrix& A, std::vector<int>& piv) {
  const int n = static_cast<int>(A.rows());
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (magnitude(A(i, k)) > magnitude(A(p, k))) p = i;
    piv[k] = p;
    if (p != k) A.row(p).swap(A.row(k));
    const auto inv = 1.0 / A(k, k);  // a zero pivot gives non-finite solutions, checked there
    for (int i = k + 1; i < n; ++i) A(i, k) *= inv;
    for (int j = k + 1; j < n; ++j) {
      const auto a = A(k, j);
      for (int i = k + 1; i < n; ++i) A(i, j) -= A(i, k) * a;
    }
  }
}

template <class Matrix, class Vector>
void lu_solve(const Matrix& LU, const std::vector<int>& piv, Vector& x) {
  const int n = static_cast<int>(LU.rows());
  for (int k = 0; k < n; ++k)
    if (piv[k] != k) std::swap(x[k], x[piv[k]]);
  for (int k = 0; k < n; ++k)
    for (int i = k + 1; i < n; ++i) x[i] -= LU(i, k) * x[k];
  for (int k = n - 1; k >= 0; --k) {
    x[k] /= LU(k, k);
    for (int i = 0; i < k; ++i) x[i] -= LU(i, k) * x[k];
  }
}

}  // namespace

void Radau5::factorize(double h) {
  const Tableau& tb = tableau();
  sigma1_ = tb.L(0, 0) / h;
  sigma2_ = std::complex<double>(tb.L(1, 1), tb.L(2, 1)) / h;
  reduced_matrix(J_, m_, sigma1_, E1_, G1_);
  lu_factor(E1_, piv_real_);
  reduced_matrix(J_, m_, sigma2_, E2_, G2_);
  lu_factor(E2_, piv_complex_);
  ++stats_.ndec;
}

void Radau5::solve_real(const Eigen::VectorXd& r, Eigen::VectorXd& x) {
  const int m = m_, k = n_ - m_;
  rr_ = r.tail(k);
  rr_.noalias() += G1_ * r.head(m);
  lu_solve(E1_, piv_real_, rr_);
  x.head(k) = rr_;
  x.tail(m) = sigma1_ * rr_.head(m) - r.head(m);
}

void Radau5::solve_complex(Eigen::VectorXcd& r) {
  const int m = m_, k = n_ - m_;
  cr_ = r.tail(k);
  cr_.noalias() += G2_ * r.head(m);
  lu_solve(E2_, piv_complex_, cr_);
  r.tail(m) = sigma2_ * cr_.head(m) - r.head(m);
  r.head(k) = cr_;
}

// Starting values of the Newton iterations: zero, or the previous step's collocation polynomial
// extrapolated to the new stage times (Hairer's STARTN = false).
void Radau5::starting_values(double h) {
  const Tableau& tb = tableau();
  for (int i = 0; i < 3; ++i) {
    if (!have_polynomial_) {
      z_[i].setZero();
      continue;
    }
    const double s = tb.c[i] * h / h_old_;
    z_[i] = s * (poly_[0] + (s - (tb.c[1] - 1.0)) * (poly_[1] + (s - (tb.c[0] - 1.0)) * poly_[2]));
  }
  for (int j = 0; j < 3; ++j) w_[j] = tb.TI(j, 0) * z_[0] + tb.TI(j, 1) * z_[1] + tb.TI(j, 2) * z_[2];
}

// Simplified Newton iterations for Z at (t, y) with step h (factorizations for h in place):
// Accepted when converged, SlowNewton when the convergence is too slow for the step
// (slow_factor_ proposes the reduction), Failed when diverging or failing.
Radau5::Attempt Radau5::newton(const Rhs& f, double t, double h, const Eigen::VectorXd& y) {
  const Tableau& tb = tableau();
  scale_ = atol_.array() + rtol_.array() * y.array().abs();
  newton_divisors(scale_, fnewt_, newton_scale_);
  starting_values(h);
  faccon_ = std::pow(std::max(faccon_, kRound), 0.8);
  theta_ = theta_reuse_;
  double dyno_old = 0.0, thq_old = 0.0;
  for (int it = 1; it <= kMaxNewton; ++it) {
    ++stats_.nnewton;
    newton_its_ = it;
    for (int i = 0; i < 3; ++i) {
      y_stage_ = y + z_[i];
      if (!eval(f, t + tb.c[i] * h, y_stage_, fz_[i])) return Attempt::Failed;
    }
    // Right-hand sides of the transformed system, T^-1 F(Z) - Λ W / h; the increments of W
    // then overwrite fz_.
    tmp_ = tb.TI(0, 0) * fz_[0] + tb.TI(0, 1) * fz_[1] + tb.TI(0, 2) * fz_[2] - (tb.L(0, 0) / h) * w_[0];
    ctmp_.real() = tb.TI(1, 0) * fz_[0] + tb.TI(1, 1) * fz_[1] + tb.TI(1, 2) * fz_[2] -
                   (tb.L(1, 1) * w_[1] + tb.L(1, 2) * w_[2]) / h;
    ctmp_.imag() = tb.TI(2, 0) * fz_[0] + tb.TI(2, 1) * fz_[1] + tb.TI(2, 2) * fz_[2] -
                   (tb.L(2, 1) * w_[1] + tb.L(2, 2) * w_[2]) / h;
    solve_real(tmp_, fz_[0]);
    solve_complex(ctmp_);
    fz_[1] = ctmp_.real();
    fz_[2] = ctmp_.imag();
    if (!(fz_[0].allFinite() && fz_[1].allFinite() && fz_[2].allFinite())) {
      failure_ = "singular Newton matrix";
      return Attempt::Failed;
    }
    double sum = 0.0;
    for (int j = 0; j < 3; ++j) sum += (fz_[j].array() / newton_scale_.array()).square().sum();
    const double dyno = std::sqrt(sum / (3.0 * n_));
    if (it > 1 && it < kMaxNewton) {
      const Contraction c = newton_contraction(it, dyno, dyno_old, thq_old, fnewt_);
      if (c == Contraction::Diverges) return Attempt::Failed;
      if (c == Contraction::TooSlow) return Attempt::SlowNewton;
    }
    dyno_old = std::max(dyno, kRound);
    for (int j = 0; j < 3; ++j) w_[j] += fz_[j];
    for (int i = 0; i < 3; ++i) z_[i] = tb.T(i, 0) * w_[0] + tb.T(i, 1) * w_[1] + tb.T(i, 2) * w_[2];
    if (faccon_ * dyno <= fnewt_) return Attempt::Accepted;
  }
  failure_ = "Newton iterations did not converge";
  return Attempt::Failed;
}

// err_ = scaled norm of the filtered error estimate; with `refine` (first step, or after a
// rejection) a large estimate is improved once by one more filtering through f (Hairer).
bool Radau5::estimate_error(const Rhs& f, double t, double h, const Eigen::VectorXd& y, bool refine) {
  const Tableau& tb = tableau();
  y_new_ = y + z_[2];
  scale_ = atol_.array() + rtol_.array() * y.array().abs().max(y_new_.array().abs());
  dz_ = (tb.d[0] * z_[0] + tb.d[1] * z_[1] + tb.d[2] * z_[2]) / h;
  tmp_ = f0_ + dz_;
  solve_real(tmp_, err_v_);
  err_ = std::max(scaled_rms(err_v_, scale_), kMinError);
  if (err_ >= 1.0 && refine) {
    y_stage_ = y + err_v_;
    if (!eval(f, t, y_stage_, tmp_)) return false;
    tmp_ += dz_;
    solve_real(tmp_, err_v_);
    err_ = std::max(scaled_rms(err_v_, scale_), kMinError);
  }
  if (std::isfinite(err_)) return true;
  failure_ = "non-finite error estimate";
  return false;
}

Radau5::Attempt Radau5::attempt_step(const Rhs& f, double t, double h, const Eigen::VectorXd& y, bool refine) {
  const Attempt converged = newton(f, t, h, y);
  if (converged != Attempt::Accepted) return converged;
  if (!estimate_error(f, t, h, y, refine)) return Attempt::Failed;
  if (err_ >= 1.0) {
    failure_ = "local error above tolerance";
    return Attempt::ErrorTooLarge;
  }
  // f at the new state starts the next step's error estimate; a failure there rejects the step.
  if (!eval(f, t + h, y_new_, tmp_)) return Attempt::Failed;
  return Attempt::Accepted;
}

// Newton form of the collocation polynomial u through (t, y) and the stages, in
// s = (t' - t_new) / h on [-1, 0]: u(s) = y_new + s (p0 + (s - c2 + 1) (p1 + (s - c1 + 1) p2)).
void Radau5::build_polynomial() {
  const Tableau& tb = tableau();
  const double c1 = tb.c[0], c2 = tb.c[1];
  Eigen::VectorXd& d21 = y_stage_;  // work space
  Eigen::VectorXd& d10 = err_v_;
  poly_[0] = (z_[1] - z_[2]) / (c2 - 1.0);   // u[0, c2-1]
  d21 = (z_[0] - z_[1]) / (c1 - c2);         // u[c2-1, c1-1]
  d10 = z_[0] / c1;                          // u[c1-1, -1]
  poly_[1] = (poly_[0] - d21) / (1.0 - c1);  // u[0, c2-1, c1-1]
  poly_[2] = poly_[1] - (d21 - d10) / c2;    // u[0, c2-1, c1-1, -1]
}

void Radau5::polynomial_value(double s) {
  const Tableau& tb = tableau();
  y_out_ = y_new_ + s * (poly_[0] + (s - (tb.c[1] - 1.0)) * (poly_[1] + (s - (tb.c[0] - 1.0)) * poly_[2]));
}

size_t Radau5::emit_outputs(const std::vector<double>& touts, size_t next, double t_new, const Output& out) {
  for (; next < touts.size() && touts[next] <= t_new; ++next) {
    if (touts[next] == t_new) {
      out(t_new, y_new_);
    } else {
      polynomial_value((touts[next] - t_new) / h_old_);
      out(touts[next], y_out_);
    }
  }
  return next;
}

void Radau5::check_ready() const {
  if (!jac_) throw std::invalid_argument("Radau5: no Jacobian callback set");
}

void Radau5::begin() {
  first_ = true;
  rejected_ = false;
  need_jacobian_ = true;
  jacobian_fresh_ = false;
  h_factorized_ = h_acc_ = err_acc_ = 0.0;
  accepted_here_ = 0;
  have_polynomial_ = false;
  faccon_ = 1.0;
  nonstiff_steps_ = 0;
  rho_ = 0.0;
}

bool Radau5::start(const Rhs& f, double t0, const Eigen::VectorXd& y) { return eval(f, t0, y, f0_); }

double Radau5::first_step(const Rhs& f, double t0, double t_end, const Eigen::VectorXd& y) {
  return std::min(h_initial_ > 0 ? h_initial_ : initial_step(f, t0, t_end, y), hmax_);
}

Stepper::Outcome Radau5::step(const Rhs& f, double t, double h_try, double t_new, Eigen::VectorXd& y,
                              Outputs& outputs, double& h) {
  Attempt result = Attempt::Failed;
  try {
    if (need_jacobian_) {
      ++stats_.njev;
      jac_(t, y, J_);
      if (J_.rows() != n_ || J_.cols() != n_) throw std::invalid_argument("Radau5: the Jacobian has the wrong size");
      if (!J_.allFinite()) throw IntegrationError("Radau5: non-finite Jacobian at " + describe_step(t, h_try));
      need_jacobian_ = false;
      jacobian_fresh_ = true;
      if (nonstiff_bound_ > 0) {
        eigen_.compute(J_, false);
        // No convergence of the eigenvalues: take the method for stiff (no return).
        rho_ = eigen_.info() == Eigen::Success ? eigen_.eigenvalues().cwiseAbs().maxCoeff()
                                               : std::numeric_limits<double>::infinity();
      }
      h_factorized_ = 0.0;
    }
    if (h_try != h_factorized_) {
      factorize(h_try);
      h_factorized_ = h_try;
    }
    result = attempt_step(f, t, h_try, y, first_ || rejected_);
  } catch (const StepRejected& e) {
    failure_ = e.what();
    result = Attempt::Failed;
  }

  // Hairer's step-size proposal: the error behaves as h^4; fewer Newton iterations, more trust.
  const double fac = std::min(kStepSafety, kStepSafety * (1 + 2 * kMaxNewton) / (newton_its_ + 2 * kMaxNewton));
  double quot = std::clamp(std::pow(err_, 0.25) / fac, 0.125, 5.0);
  if (result != Attempt::Accepted) {
    rejected_ = true;
    if (result == Attempt::ErrorTooLarge) h = first_ ? 0.1 * h_try : h_try / quot;
    else if (result == Attempt::SlowNewton) h = h_try * slow_factor_;
    else h = 0.5 * h_try;
    // A Jacobian from an earlier state may be why Newton failed: take it afresh at this state.
    // (Hairer's code renews it after any rejection; a step rejected for its error had converged,
    // and here a Jacobian is a linearization costing several right-hand sides per DOF.)
    need_jacobian_ = !jacobian_fresh_ && result != Attempt::ErrorTooLarge;
    return Outcome::Rejected;
  }

  ++accepted_here_;
  if (accepted_here_ > 1) {
    // Predictive controller (Gustafsson): use the trend of the last two errors.
    const double gus = std::clamp((h_acc_ / h_try) * std::pow(err_ * err_ / err_acc_, 0.25) / kStepSafety, 0.125, 5.0);
    quot = std::max(quot, gus);
  }
  h_acc_ = h_try;
  err_acc_ = std::max(1e-2, err_);
  double h_new = std::min(h_try / quot, hmax_);
  if (rejected_) h_new = std::min(h_new, h_try);

  h_old_ = h_try;
  build_polynomial();
  have_polynomial_ = true;
  outputs.next = emit_outputs(outputs.touts, outputs.next, t_new, outputs.out);
  y = y_new_;
  f0_ = tmp_;  // f(t_new, y_new) from attempt_step
  first_ = rejected_ = false;
  jacobian_fresh_ = false;
  // Keep the Jacobian if Newton contracted fast; keep the step (and the factorizations) too
  // if the proposal is only a little larger.
  need_jacobian_ = theta_ > theta_reuse_;
  if (!need_jacobian_ && h_new >= h_try && h_new <= 1.2 * h_try) h_new = h_try;
  h = h_new;
  if (nonstiff_bound_ > 0) nonstiff_steps_ = rho_ * h_try <= nonstiff_bound_ ? nonstiff_steps_ + 1 : 0;
  return Outcome::Accepted;
}

bool Radau5::switch_after_step(double t, double t_end, double) {
  return nonstiff_bound_ > 0 && nonstiff_steps_ >= kNonstiffSteps && t < t_end;
}

}  // namespace spacar
