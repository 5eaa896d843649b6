// The static analysis (statics.hpp): the path of equilibria from λ = 0 to 1, by Newton at each
// load factor with load steps cut where it fails, or by the arc-length method past limit points,
// with the stability of each equilibrium from the tangent's inertia. The forces and the
// compliance are in statics_forces.cpp.
#include "spacar/analyses/statics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "spacar/recursive/chain.hpp"
#include "spacar/kinematics/dynamics.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/limits.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/analyses/nodal.hpp"


namespace spacar {

namespace {

// Newton's iterations for one load factor from the current state, and the state to go back to.
// The tangent stiffness K = K0 + G0 of the degrees of freedom is never formed: its solves go
// through the sparse saddle-point system of the nodal coordinates (nodal.hpp), a load in q
// represented on the coordinates and the solution read back in q.
class EquilibriumPath {
 public:
  // `reduced`: the saddle-point system of sys and data (its pattern and ordering made once);
  // `chain`: the system's open chain (ExplicitChain::detect), or nullptr.
  EquilibriumPath(const System& sys, Data& data, const StaticOptions& opt, StaticResults& res, ReducedSystem& reduced,
                  ExplicitChain* chain)
      : sys_(sys), data_(data), opt_(opt), res_(res), nd_(sys.n_dof()), reduced_(reduced), tangent_(reduced.saddle()),
        chain_(chain), scale_(dof_scale(sys)) {
    // Inputs at the block start (λ = 0) and end (λ = 1), ordered as input_cols.
    const double tp = sys.settings.timestep_tp;
    p0_ = sys.p0;
    p1_ = sys.p0 + tp * sys.pd0 + 0.5 * tp * tp * sys.pdd0;
  }

  struct Attempt {
    bool converged = false;
    int iterations = 0;
    std::string why;            // why Newton failed
    int worst = -1;             // DOF of the largest (scaled) residual
    double worst_residual = 0.0;
    bool singular_at_start = false;
  };

  // At the starting state (assembled, λ = 0): the generalized forces R0 that hold it there, zero
  // for an unloaded stress-free start, the equilibrium of the block before otherwise. The path
  // solves R(q, λ) − (1 − λ) R0 = 0: it begins exactly at the current state, and from one block
  // to the next the loads change gradually instead of being released and applied again.
  void start() { static_forces(sys_, data_, 0.0, R0_, nullptr, nullptr, chain_); }

  // Equilibrium at load factor λ, starting from the current state. The sign of det K must stay
  // that of the start: a change during the iterations means that the step crosses a limit or
  // bifurcation point, and Newton may land on a distant branch (a snap-through). Such a step
  // fails unless `last_chance` (the smallest step): then an end beyond a bifurcation, where the
  // sign has changed, is accepted (an unstable equilibrium, reported as indefinite), while a
  // return to the start's sign (the jump past a limit point) fails.
  // `from`: the load factor of the current state, for the predictor of moving inputs.
  Attempt solve(double lambda, bool last_chance, double from) {
    Attempt a;
    Eigen::VectorXd qhat = with_inputs(data_.qhat, lambda);
    Eigen::VectorXd R, dq, dx;
    int start_sign = 0, last_sign = 0;
    // The predictor factorizes the tangent at the step's start: its sign is the start's.
    const bool predicted = predict(from, lambda, qhat, dx, start_sign);
    double last_correction = std::numeric_limits<double>::infinity();
    double last_residual = std::numeric_limits<double>::infinity();
    bool crossed = false;
    bool fresh = false;  // the factorization is that of the previous iterate
    for (int it = 0;; ++it) {
      check_thread_deadline("(in the static analysis)");
      try {
        place(qhat, it > 0 || predicted ? &dx : nullptr);
      } catch (const KinematicsError& err) {
        a.why = std::string("the kinematics has no solution there (") + err.what() + ")";
        return a;
      }
      const double force = forces_here(lambda, R);
      const Eigen::VectorXd Rs = scale_.cwiseProduct(R);
      if (!Rs.allFinite()) {
        a.why = "the forces or the stiffness are not finite";
        return a;
      }
      // Converged on the residual: small against the forces it balances, or near it once the
      // corrections have reached round-off.
      auto residual_converged = [&](double r) {
        return r <= opt_.tolerance * force || (last_correction <= 1e-12 && r <= 1e-6 * force);
      };
      // A converged step that ends with the determinant's sign of its start after a crossing has
      // jumped past a limit point.
      auto converged = [&](int sign) {
        if (crossed && sign == start_sign)
          a.why = "past a limit point: the only equilibrium found lies on a distant branch (a snap-through)";
        else
          a.converged = true;
        return a;
      };
      // Converged after a small Newton correction: the last tangent factorized, at most two
      // corrections away (each below 1e-4 of the DOFs' scale; about √tolerance when Newton
      // converges quadratically; two after the chord below), stands for this state's in the
      // checks of its determinant's sign and of stability (indefinite()), and the factorization
      // at the solution (a sixth of the work of a solve in five iterations) is not made. Not
      // after the first iteration: its tangent is the one at the start of the step (the previous
      // load), on the other side of any critical point the step passes (a linear problem
      // converges there).
      int worst = -1;  // the DOF of the largest scaled residual
      const double residual = nd_ > 0 ? Rs.cwiseAbs().maxCoeff(&worst) : 0.0;
      if (it >= 2 && last_correction <= 1e-4 && nd_ > 0 && factorized_ && residual_converged(residual))
        return converged(last_sign);
      // The last correction by the chord: the factorization of the previous iterate, a small
      // correction away (as above), where the chord should end below the tolerance: near the
      // solution it contracts the residual by about the ratio r_k / r_k−1 of the last Newton
      // step, here with a factor 10 to spare. The last Newton iteration then costs no
      // factorization (4-6 % of a cold static solve of a cantilever); if the chord falls short,
      // the next iteration factorizes again.
      const bool chord = it >= 2 && fresh && last_correction <= 1e-4 && factorized_ && !tangent_.singular() &&
                         10.0 * residual * (residual / last_residual) <= opt_.tolerance * force;
      fresh = !chord;
      last_residual = residual;
      if (!chord) {
        factorize_here(lambda);
        if (!factorized_) {
          a.why = "the forces or the stiffness are not finite";
          return a;
        }
        const int sign = tangent_.singular() || nd_ == 0 ? 0 : tangent_.sign_determinant();
        if (it == 0 && !predicted) start_sign = sign;
        else if (sign != start_sign) crossed = true;
        last_sign = sign;
        if (crossed && !last_chance) {
          a.why = "the tangent stiffness changes the sign of its determinant within the step (a limit or "
                  "bifurcation point)";
          return a;
        }
      }
      const bool singular = tangent_.singular();
      double correction = 0.0;
      if (nd_ > 0) {
        a.worst = worst;
        a.worst_residual = R[worst];
        if (!singular) {
          solve_dofs(-R, dq, dx);
          correction = dq.cwiseQuotient(scale_).cwiseAbs().maxCoeff();
        }
      }
      // Converged on the residual, or the correction would move the DOFs by less than round-off
      // (nothing is loaded: a mechanism moved by its inputs).
      if (residual_converged(residual) || (!singular && correction <= 1e-13)) return converged(last_sign);
      if (it == opt_.max_iterations) {
        a.why = "Newton's method did not converge in " + std::to_string(opt_.max_iterations) + " iterations";
        return a;
      }
      if (singular) {
        a.why = "the tangent stiffness is singular: no stiffness in " + singular_directions();
        a.singular_at_start = it == 0;
        return a;
      }
      ++a.iterations;
      ++res_.newton_iterations;
      last_correction = correction;
      for (int j = 0; j < nd_; ++j) qhat[sys_.dof_cols[j]] += dq[j];
    }
  }

  // The tangent stiffness of the last evaluation has a negative eigenvalue: the equilibrium is
  // unstable. For a symmetric stiffness (conservative loads) its inertia, counted by the
  // symmetric factorization, decides. Torques (TORQUEL, TORQUEG) make it unsymmetric and only
  // the sign of its determinant is known: a negative determinant means a real negative
  // eigenvalue (a divergence instability); a pair of complex eigenvalues with negative real
  // parts (flutter) is not detected. Returns "" or the description of the direction of the
  // eigenvalue nearest zero (inverse iteration).
  std::string indefinite() {
    if (nd_ == 0 || !factorized_) return "";
    check_thread_deadline("(in the static analysis)");
    const int negative = tangent_.negative_eigenvalues();
    if (negative == 0 || (negative < 0 && tangent_.sign_determinant() >= 0)) return "";
    double value = 0.0;
    const Eigen::VectorXd dx = tangent_.lowest_direction(8, value);
    std::string how = negative > 0 ? std::to_string(negative) + " negative eigenvalue" + (negative > 1 ? "s" : "")
                                   : std::string("a negative determinant");
    return directions(dofs_scaled(dx)) + " (" + how + ")";
  }

  // For the arc-length method: the state with the DOFs (and inputs) at q̂, at load factor λ
  // (positions predicted by dx from the current ones, if given): the scaled residual of the path
  // Fs = S (R − (1 − λ) R0), its derivative in λ at fixed q, gs = S (−DF_qᵀ f + R0 + the
  // tangent's response to the inputs' motion), and the tangent factorized. Returns the force
  // scale.
  double evaluate(const Eigen::VectorXd& qhat, double lambda, const Eigen::VectorXd* dx, Eigen::VectorXd& Fs,
                  Eigen::VectorXd& gs) {
    place(with_inputs(qhat, lambda), dx);
    Eigen::VectorXd R, full_load;
    const double force = evaluate_here(lambda, R, &full_load);
    // ∂R/∂λ: the loads, R0, and where the inputs move with λ, the tangent along their motion
    // (the inputs are further columns of q̂; Σ σ_k H_k with the complete stresses
    // differentiates DF_q along them too): DF_qᵀ (−f + H δx_p), δx_p = DF_p (p1 − p0).
    Eigen::VectorXd g = -full_load;
    if (sys_.n_input() > 0 && p1_ != p0_) {
      Eigen::VectorXd rate = Eigen::VectorXd::Zero(sys_.n_qhat()), dx_p;
      for (int i = 0; i < sys_.n_input(); ++i) rate[sys_.input_cols[i]] = p1_[i] - p0_[i];
      if (chain_) chain_->transfer_times(sys_, data_, rate, dx_p);
      else transfer_times(sys_, data_, rate, dx_p);
      NodalCoefficients c;
      c.load_factor = lambda;
      g += nodal_matrix(sys_, data_, data_.sigma, c) * dx_p;
    }
    Eigen::VectorXd out;
    if (chain_) chain_->transfer_transposed(sys_, data_, g, out);
    else transfer_transposed(sys_, data_, g, out);
    R -= (1.0 - lambda) * R0_;
    Fs = scale_.cwiseProduct(R);
    gs.resize(nd_);
    for (int j = 0; j < nd_; ++j) gs[j] = scale_[j] * (out[sys_.dof_cols[j]] + R0_[j]);
    return force;
  }
  // The first-order predictor of a step whose inputs move: the DOFs' change dq = −K⁻¹ ∂R/∂λ Δλ
  // from the current equilibrium at `from` (added to qhat) and the coordinates' change dx with it.
  // Without it Newton starts from the DOFs of the last step with only the inputs moved: where the
  // DOFs are deformations (DYNE), the released deformations next to the input then take the
  // whole motion, and Newton needs dozens of iterations and step cuts to spread it.
  bool predict(double from, double lambda, Eigen::VectorXd& qhat, Eigen::VectorXd& dx, int& start_sign) {
    if (nd_ == 0 || sys_.n_input() == 0 || p1_ == p0_ || lambda == from) return false;
    Eigen::VectorXd Fs, gs, dq;
    try {
      evaluate(data_.qhat, from, nullptr, Fs, gs);
    } catch (const KinematicsError&) {
      return false;
    }
    if (!factorized_ || tangent_.singular()) return false;
    start_sign = tangent_.sign_determinant();
    solve_dofs(-(lambda - from) * gs.cwiseQuotient(scale_), dq, dx);
    if (!dq.allFinite() || !dx.allFinite()) return false;
    for (int j = 0; j < nd_; ++j) qhat[sys_.dof_cols[j]] += dq[j];
    return true;
  }
  bool factorized() const { return factorized_; }
  bool singular() const { return tangent_.singular(); }
  const Eigen::VectorXd& scale() const { return scale_; }
  // dy = Ks⁻¹ rs for the scaled tangent Ks = S K S of the last evaluation, and dx, the change of
  // the coordinates for the change S dy of the DOFs.
  void solve_scaled(const Eigen::VectorXd& rs, Eigen::VectorXd& dy, Eigen::VectorXd& dx) {
    solve_dofs(rs.cwiseQuotient(scale_), dy, dx);
    dy = dy.cwiseQuotient(scale_);
  }
  // "the direction of ..." of the singular tangent of the last evaluation.
  std::string singular_directions() {
    const Eigen::VectorXd dx = tangent_.null_direction();
    if (dx.size() == 0) return "a direction not located (an unsymmetric tangent)";
    return directions(dofs_scaled(dx));
  }

  struct Snapshot {
    Eigen::VectorXd x, qhat, angle_ref;
  };
  Snapshot save() const { return {data_.x, data_.qhat, data_.angle_ref}; }
  void restore(const Snapshot& s) {
    data_.x = s.x;
    data_.qhat = s.qhat;
    data_.angle_ref = s.angle_ref;
  }

 private:
  // The state at the current positions for load factor λ: R − (1 − λ) R0 and the tangent
  // factorized.
  double evaluate_here(double lambda, Eigen::VectorXd& R, Eigen::VectorXd* full_load = nullptr) {
    const double force = forces_here(lambda, R, full_load);
    factorize_here(lambda);
    return force;
  }
  double forces_here(double lambda, Eigen::VectorXd& R, Eigen::VectorXd* full_load = nullptr) {
    const double force = static_forces(sys_, data_, lambda, R, nullptr, full_load, chain_);
    R -= (1.0 - lambda) * R0_;
    return force;
  }
  void factorize_here(double lambda) {
    NodalCoefficients c;
    c.load_factor = lambda;
    check_thread_deadline("(in the static analysis)");
    factorized_ = reduced_.factorize(data_.sigma, c);
  }

  // dq = K⁻¹ v and dx = DF_q dq for a vector v of generalized forces of the DOFs (ReducedSystem),
  // unrefined: Newton's residuals are exact, its steps need not be.
  void solve_dofs(const Eigen::VectorXd& v, Eigen::VectorXd& dq, Eigen::VectorXd& dx) { reduced_.solve(v, dq, dx, 0); }

  Eigen::VectorXd dofs_scaled(const Eigen::VectorXd& dx) const { return reduced_.dofs(dx).cwiseQuotient(scale_); }

  // q̂ with the inputs at their values for load factor λ (moved linearly from p0 to p1).
  Eigen::VectorXd with_inputs(Eigen::VectorXd qhat, double lambda) const {
    for (int i = 0; i < sys_.n_input(); ++i) qhat[sys_.input_cols[i]] = p0_[i] + lambda * (p1_[i] - p0_[i]);
    return qhat;
  }

  // Positions for q̂: the coordinates moved by the predicted change dx (the first-order change
  // for the step of the DOFs, if known), then the constraints solved by Newton.
  void place(const Eigen::VectorXd& qhat, const Eigen::VectorXd* dx) {
    if (dx) data_.x += *dx;
    data_.qhat = qhat;
    for (int g : sys_.x_input) data_.x[g] = qhat[sys_.qhat_col_x[g]];
    for (int g : sys_.x_dyn) data_.x[g] = qhat[sys_.qhat_col_x[g]];
    // An open chain element by element (closed form for planar beams); otherwise full Newton on
    // the positions: the steps between static iterates are large, and the chord iteration with
    // the last velocity block (meant for small time steps) would crawl.
    const int iterations = std::max(sys_.settings.maxiterat, 50);
    const double tol = std::min(sys_.settings.epskin, 1e-10);
    data_.jacobian_reusable = false;
    if (chain_) chain_->solve_positions(sys_, data_, iterations, tol);
    else solve_positions(sys_, data_, iterations, tol, false);
    res_.kinematic_iterations += data_.newton_iterations;
  }

  std::string directions(const Eigen::MatrixXd& V) const { return dof_directions(sys_, V); }

  const System& sys_;
  Data& data_;
  const StaticOptions& opt_;
  StaticResults& res_;
  const int nd_;
  ReducedSystem& reduced_;
  SaddlePoint& tangent_;   // reduced_'s saddle-point system
  ExplicitChain* chain_;   // the kinematics of an open chain; nullptr otherwise
  bool factorized_ = false;
  Eigen::VectorXd scale_;        // characteristic size of each DOF: lengths vs angles
  Eigen::VectorXd p0_, p1_;
  Eigen::VectorXd R0_;           // generalized forces at the start (see start())
};

// Riks' normal-plane arc-length method on y = (q_s, μ), q_s the DOFs divided by their scale
// and μ = c λ, c the size of dq_s/dλ at the start (so that a first step weighs displacement and
// load alike). Each step predicts along the unit tangent τ of the last point and corrects by
// Newton on the residual bordered with τᵀ (y − y_predicted) = 0: the bordered matrix stays
// regular at limit points, where K alone is singular. The tangent at a new point solves the
// same bordered system with the previous tangent, τ_oldᵀ τ > 0: the path goes on in the
// direction it came from, λ falling after a limit point. The step length follows the Newton
// iterations; a failed step is halved. The bordered systems are solved by block elimination
// with two solves of the tangent (EquilibriumPath::solve_scaled).
class ArcLength {
 public:
  ArcLength(const System& sys, EquilibriumPath& path, const StaticOptions& opt, StaticResults& res)
      : sys_(sys), path_(path), opt_(opt), res_(res), nd_(sys.n_dof()) {}

  struct Point {
    EquilibriumPath::Snapshot state;
    double lambda = 0.0;
    Eigen::VectorXd tau;   // unit tangent in y
    Eigen::VectorXd x_tau; // the change of the coordinates per unit step along it
  };

  // The starting point (the current state at λ = 0), its tangent, c and the first step length
  // (the one that raises λ by 1/steps along the tangent).
  Point start(const Eigen::VectorXd& qhat) {
    Point p;
    Eigen::VectorXd Fs;
    path_.evaluate(qhat, 0.0, nullptr, Fs, gs_);
    check_thread_deadline("(in the static analysis)");
    if (nd_ > 0 && (!path_.factorized() || path_.singular()))
      throw StaticError("arc-length continuation needs a regular tangent stiffness at the start; it is singular in " +
                        path_.singular_directions());
    c_ = 1.0;
    if (nd_ > 0) {
      Eigen::VectorXd dy, dx;
      path_.solve_scaled(-gs_, dy, dx);
      c_ = dy.norm();
    }
    if (!(c_ > 0.0) || !std::isfinite(c_)) c_ = 1.0;  // nothing loaded: λ alone
    Eigen::VectorXd e = Eigen::VectorXd::Zero(nd_ + 1);
    e[nd_] = 1.0;
    p.state = path_.save();
    tangent(e, p);
    first_length_ = c_ / opt_.steps / p.tau[nd_];
    return p;
  }
  double first_length() const { return first_length_; }

  struct Step {
    bool converged = false;
    int iterations = 0;
    std::string why;
    int worst = -1;
    double worst_residual = 0.0;
  };

  // From point a (the state restored to it), a step of length ds: the new point in `b`.
  Step step(const Point& a, double ds, Point& b) {
    path_.restore(a.state);
    Eigen::VectorXd qhat = a.state.qhat;
    const Eigen::VectorXd& scale = path_.scale();
    for (int j = 0; j < nd_; ++j) qhat[sys_.dof_cols[j]] += scale[j] * ds * a.tau[j];
    double lambda = a.lambda + ds * a.tau[nd_] / c_;
    Step s = correct(qhat, lambda, a.tau, ds * a.x_tau);
    if (!s.converged) return s;
    b.state = path_.save();
    b.lambda = lambda;
    tangent(a.tau, b);
    if (!b.tau.allFinite()) {
      s.converged = false;
      s.why = "the tangent of the path is not defined there";
    } else if (b.tau.dot(a.tau) < 0.5) {  // turned by more than 60°: the step may have left the path
      s.converged = false;
      s.why = "the path turns too sharply within the step";
    }
    return s;
  }

  // The limit point between a and b (the λ component of the tangent changes sign): Illinois'
  // regula falsi on the step length for τ_λ = 0. Returns the extreme λ found (λ is stationary
  // there, so its error is quadratic in that of the step length). Leaves the state anywhere.
  double limit_point(const Point& a, const Point& b, double ds) {
    double lo = 0.0, hi = ds, f_lo = a.tau[nd_], f_hi = b.tau[nd_];
    const bool maximum = a.tau[nd_] > 0.0;
    double extreme = maximum ? std::max(a.lambda, b.lambda) : std::min(a.lambda, b.lambda);
    int side = 0;
    for (int it = 0; it < 60 && hi - lo > 1e-9 * ds; ++it) {
      double s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
      if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
      Point p;
      if (!step(a, s, p).converged) break;
      extreme = maximum ? std::max(extreme, p.lambda) : std::min(extreme, p.lambda);
      const double f = p.tau[nd_];
      if (f == 0.0) break;
      if ((f > 0.0) == (f_lo > 0.0)) {
        lo = s, f_lo = f;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        hi = s, f_hi = f;
        if (side == 1) f_lo *= 0.5;
        side = 1;
      }
    }
    return extreme;
  }

 private:
  // Newton on [F(q, λ); nᵀ (y − y0)] = 0 from y0 = (q̂, λ), the coordinates predicted by dx.
  Step correct(Eigen::VectorXd qhat, double& lambda, const Eigen::VectorXd& n, Eigen::VectorXd dx) {
    Step s;
    const Eigen::VectorXd& scale = path_.scale();
    Eigen::VectorXd Fs, dy;
    double last_correction = std::numeric_limits<double>::infinity();
    for (int it = 0;; ++it) {
      check_thread_deadline("(in the static analysis)");
      double force = 0.0;
      try {
        force = path_.evaluate(qhat, lambda, &dx, Fs, gs_);
      } catch (const KinematicsError& err) {
        s.why = std::string("the kinematics has no solution there (") + err.what() + ")";
        return s;
      }
      if (!Fs.allFinite() || !gs_.allFinite() || !path_.factorized()) {
        s.why = "the forces or the stiffness are not finite";
        return s;
      }
      double res_max = 0.0;
      if (nd_ > 0) {
        res_max = Fs.cwiseAbs().maxCoeff(&s.worst);
        s.worst_residual = Fs[s.worst] / scale[s.worst];
      }
      if (!bordered(n, -Fs, 0.0, dy, dx)) {
        s.why = "the bordered tangent is singular";
        return s;
      }
      // The largest change of a scaled DOF or of λ.
      const double correction = std::max(nd_ > 0 ? dy.head(nd_).cwiseAbs().maxCoeff() : 0.0, std::abs(dy[nd_]) / c_);
      if (res_max <= opt_.tolerance * force || correction <= 1e-13 ||
          (last_correction <= 1e-12 && res_max <= 1e-6 * force)) {
        s.converged = true;
        return s;
      }
      if (it == opt_.max_iterations) {
        s.why = "Newton's method did not converge in " + std::to_string(opt_.max_iterations) + " iterations";
        return s;
      }
      ++s.iterations;
      ++res_.newton_iterations;
      last_correction = correction;
      for (int j = 0; j < nd_; ++j) qhat[sys_.dof_cols[j]] += scale[j] * dy[j];
      lambda += dy[nd_] / c_;
    }
  }

  // [y_q; y_λ] solving [K_s, g_s / c; n_qᵀ, n_λ] y = [r; ρ] at the last evaluation, and dx, the
  // change of the coordinates for y: with a = K_s⁻¹ r and b = K_s⁻¹ g_s / c, y_q = a − y_λ b and
  // y_λ = (ρ − n_qᵀ a) / (n_λ − n_qᵀ b). False if it is singular.
  bool bordered(const Eigen::VectorXd& n, const Eigen::VectorXd& r, double rho, Eigen::VectorXd& y,
                Eigen::VectorXd& dx) {
    y.resize(nd_ + 1);
    if (nd_ == 0) {
      if (n[0] == 0.0) return false;
      y[0] = rho / n[0];
      dx = Eigen::VectorXd::Zero(sys_.nx);
      return true;
    }
    if (path_.singular()) return false;
    Eigen::VectorXd a, b, dx_a, dx_b;
    path_.solve_scaled(gs_ / c_, b, dx_b);
    if (r.any()) path_.solve_scaled(r, a, dx_a);
    else a = Eigen::VectorXd::Zero(nd_), dx_a = Eigen::VectorXd::Zero(sys_.nx);
    const double denominator = n[nd_] - n.head(nd_).dot(b);
    y[nd_] = (rho - n.head(nd_).dot(a)) / denominator;
    y.head(nd_) = a - y[nd_] * b;
    dx = dx_a - y[nd_] * dx_b;
    return y.allFinite() && dx.allFinite();
  }

  // The unit tangent at the last evaluation, oriented by nᵀ τ > 0, into p (with x_tau).
  void tangent(const Eigen::VectorXd& n, Point& p) {
    Eigen::VectorXd t, dx;
    if (!bordered(n, Eigen::VectorXd::Zero(nd_), 1.0, t, dx)) {
      p.tau = Eigen::VectorXd::Constant(nd_ + 1, std::numeric_limits<double>::quiet_NaN());
      p.x_tau = Eigen::VectorXd::Zero(sys_.nx);
      return;
    }
    const double norm = t.norm();
    p.tau = t / norm;
    p.x_tau = dx / norm;
  }

  const System& sys_;
  EquilibriumPath& path_;
  const StaticOptions& opt_;
  StaticResults& res_;
  const int nd_;
  double c_ = 1.0, first_length_ = 0.0;
  Eigen::VectorXd gs_;
};

void check_options(const StaticOptions& o) {
  if (o.steps < 1)
    throw InputError("static: the number of load steps must be at least 1, got " + std::to_string(o.steps));
  if (o.max_iterations < 1)
    throw InputError("static: max_iterations must be at least 1, got " + std::to_string(o.max_iterations));
  if (o.max_cuts < 0 || o.max_cuts > 50)
    throw InputError("static: max_cuts must be between 0 and 50, got " + std::to_string(o.max_cuts));
  if (!(o.tolerance > 0.0 && o.tolerance < 1.0))
    throw InputError("static: the tolerance must be between 0 and 1, got " + format_number(o.tolerance));
  if (o.max_steps < 1)
    throw InputError("static: max_steps must be at least 1, got " + std::to_string(o.max_steps));
  if (!(o.time_limit >= 0.0)) throw InputError("static: the time limit must not be negative, got " + format_number(o.time_limit));
}

}  // namespace

namespace {

// The results' rows and the checks made at every converged equilibrium.
class Rows {
 public:
  Rows(const System& sys, const Data& data, EquilibriumPath& path, StaticResults& res, int capacity)
      : data_(data), path_(path), res_(res) {
    res.load.resize(capacity);
    for (RowMatrix* m : {&res.x, &res.reaction}) m->resize(capacity, sys.nx);
    for (RowMatrix* m : {&res.e, &res.sigma}) m->resize(capacity, sys.ne);
  }

  // An equilibrium reached at λ (the tangent of the last evaluation is there): is it stable?
  void converged(double lambda) {
    res_.load_reached = lambda;
    if (!std::isnan(res_.indefinite_at)) return;
    const std::string dir = path_.indefinite();
    if (dir.empty()) return;
    res_.indefinite_at = lambda;
    res_.warnings.push_back("the tangent stiffness is indefinite at load factor " + format_number(lambda) + " in " + dir +
                            ": the equilibrium is unstable (a buckling or limit load was passed)");
  }

  void store(double lambda, int iterations) {
    res_.load[rows_] = lambda;
    res_.x.row(rows_) = data_.x;
    res_.e.row(rows_) = data_.e;
    res_.sigma.row(rows_) = data_.sigma;
    res_.reaction.row(rows_) = data_.reaction;
    res_.iterations.push_back(iterations);
    ++rows_;
  }
  int count() const { return rows_; }

  void finish() {
    res_.load.conservativeResize(rows_);
    for (RowMatrix* m : {&res_.x, &res_.reaction, &res_.e, &res_.sigma}) m->conservativeResize(rows_, m->cols());
  }

 private:
  const Data& data_;
  EquilibriumPath& path_;
  StaticResults& res_;
  int rows_ = 0;
};

// λ from 0 to 1 in equal steps, a step halved when Newton fails.
void follow_load_steps(const System& sys, EquilibriumPath& path, const StaticOptions& opt, StaticResults& res,
                       Rows& rows) {
  const int n = opt.steps;
  const double nominal = 1.0 / n, smallest = nominal * std::ldexp(1.0, -opt.max_cuts);
  double lambda = 0.0, step = nominal;
  int iterations = 0;
  while (rows.count() < n) {
    const double target = static_cast<double>(rows.count() + 1) / n;
    // Land exactly on the load factor of the next row.
    const double next = lambda + step >= target - 1e-12 * nominal ? target : lambda + step;
    const EquilibriumPath::Snapshot before = path.save();
    // The last chance: the smallest step allowed, or one whose half would not change λ (with
    // max_cuts near 50 the steps fall below the round-off of λ, and halving forever would hang).
    const bool last_chance = step <= smallest * (1.0 + 1e-9) || lambda + 0.5 * step == lambda;
    const EquilibriumPath::Attempt a = path.solve(next, last_chance, lambda);
    iterations += a.iterations;
    if (!a.converged) {
      const bool hopeless = a.singular_at_start || last_chance;
      if (hopeless) {
        std::ostringstream os;
        os << "no static equilibrium found beyond load factor " << format_number(lambda) << " (of 1; tried " << format_number(next)
           << "): " << a.why;
        if (a.worst >= 0) os << "; worst residual " << format_number(a.worst_residual) << " on " << dof_name(sys, a.worst);
        if (!a.singular_at_start) {
          os << " (load step cut " << res.step_cuts << " times, down to " << format_number(step)
             << "). The load may exceed a limit point (snap-through or collapse): follow the path past it with "
                "the arc-length method (arc_length=True, --arc-length); or the model has a degree of freedom "
                "without stiffness";
        } else {
          os << ". Give that degree of freedom stiffness (ESTIFF) or a support (FIX)";
        }
        throw StaticError(os.str());
      }
      path.restore(before);
      ++res.step_cuts;
      step *= 0.5;
      continue;
    }
    lambda = next;
    rows.converged(lambda);
    if (lambda == target) {
      rows.store(lambda, iterations);
      iterations = 0;
    }
    step = std::min(2.0 * step, nominal);  // back towards the nominal step after a cut
  }
}

// The arc-length path from λ = 0 until it reaches λ = 1 (ArcLength): a row per step, limit
// points located and reported, the last row at λ = 1 exactly by Newton at fixed λ from the
// point interpolated between the steps before and after.
void follow_arc_length(const System& sys, EquilibriumPath& path, const StaticOptions& opt, StaticResults& res,
                       Rows& rows) {
  const int nd = sys.n_dof();
  ArcLength arc(sys, path, opt, res);
  ArcLength::Point a = arc.start(path.save().qhat);
  const double nominal = arc.first_length();
  double ds = nominal;
  int cuts = 0, iterations = 0, done = 0;
  while (done < opt.max_steps) {
    ArcLength::Point b;
    const ArcLength::Step s = arc.step(a, ds, b);
    iterations += s.iterations;
    if (!s.converged) {
      if (++cuts > opt.max_cuts) {
        res.load_reached = a.lambda;
        std::ostringstream os;
        os << "the arc-length method failed beyond load factor " << format_number(a.lambda) << ": " << s.why;
        if (s.worst >= 0) os << "; worst residual " << format_number(s.worst_residual) << " on " << dof_name(sys, s.worst);
        os << " (step halved " << opt.max_cuts << " times in a row)";
        throw StaticError(os.str());
      }
      ++res.step_cuts;
      ds *= 0.5;
      continue;
    }
    rows.converged(b.lambda);
    // λ turned between a and b: a limit point, located before the state moves on.
    const bool turned = (a.tau[nd] > 0.0) != (b.tau[nd] > 0.0);
    const double limit = turned ? arc.limit_point(a, b, ds) : 0.0;
    auto report_limit = [&]() {
      if (!turned) return;
      res.limit_points.push_back(limit);
      res.warnings.push_back("limit point at load factor " + format_number(limit) +
                             (b.tau[nd] < 0.0 ? " (a maximum: snap-through)" : " (a minimum)"));
    };
    if (b.lambda >= 1.0 && a.lambda < 1.0) {
      // Newton at λ = 1 from the point between a and b where λ is 1 on the chord.
      const double w = (1.0 - a.lambda) / (b.lambda - a.lambda);
      const Eigen::VectorXd qhat = (1.0 - w) * a.state.qhat + w * b.state.qhat;
      Eigen::VectorXd Fs, gs;
      path.restore(a.state);
      EquilibriumPath::Attempt last;
      try {
        path.evaluate(qhat, 1.0, nullptr, Fs, gs);
        last = path.solve(1.0, true, 1.0);
      } catch (const KinematicsError& err) {
        last.converged = false;
        last.why = std::string("the kinematics has no solution there (") + err.what() + ")";
      }
      if (last.converged) {
        report_limit();
        rows.converged(1.0);
        rows.store(1.0, iterations + last.iterations);
        return;
      }
      if (++cuts > opt.max_cuts) {  // no equilibrium at λ = 1 from there: a shorter step, or give up
        res.load_reached = a.lambda;
        throw StaticError("the arc-length method passed load factor 1 after " + format_number(a.lambda) +
                          " but Newton at load factor 1 failed from there: " + last.why + " (step halved " +
                          std::to_string(opt.max_cuts) + " times in a row)");
      }
      ++res.step_cuts;
      ds *= 0.5;
      continue;
    }
    cuts = 0;
    report_limit();
    if (turned) {  // back to b from the limit point's search
      path.restore(b.state);
      Eigen::VectorXd Fs, gs;
      path.evaluate(b.state.qhat, b.lambda, nullptr, Fs, gs);
    }
    ++done;
    rows.store(b.lambda, iterations);
    iterations = 0;
    // Next step: about four Newton iterations per step, at most twice the first length.
    const double grow = std::sqrt(4.0 / std::max(s.iterations, 1));
    ds = std::min(ds * std::clamp(grow, 0.5, 2.0), 2.0 * nominal);
    a = std::move(b);
  }
  res.load_reached = a.lambda;
  std::ostringstream os;
  os << "the arc-length method did not reach load factor 1 in " << opt.max_steps << " steps: load factor "
     << format_number(a.lambda) << " reached";
  if (!res.limit_points.empty()) {
    os << " after limit points at";
    for (double l : res.limit_points) os << " " << format_number(l);
  }
  os << ". Allow more steps (max_steps) or longer ones (fewer steps)";
  throw StaticError(os.str());
}

}  // namespace

namespace {

// The rows of the results: one per load step; arc length: at most one per step and the last at λ = 1.
int result_rows(const StaticOptions& opt) { return opt.arc_length ? opt.max_steps + 1 : opt.steps; }

// The memory of a static analysis checked before it is set up or run: the dense arrays its
// checks may need, and with `opt` the rows of its results.
void require_static_memory(const System& sys, const StaticOptions* opt) {
  const int n = opt ? result_rows(*opt) : 0;
  std::string what = "the static analysis of " + std::to_string(sys.nx) + " nodal coordinates and " +
                     std::to_string(sys.ne) + " deformations";
  if (opt) what += " in " + std::to_string(n) + " load steps";
  require_memory(Data::estimate_dense_bytes(sys) + 8.0 * n * (2.0 * sys.nx + 2.0 * sys.ne + 2.0), what,
                 !opt ? "" : opt->arc_length ? "allow fewer steps (max_steps)" : "use fewer load steps");
}

}  // namespace

StaticSolver::StaticSolver(Model& model, const StaticOptions* first) : sim_(model) {
  const System& sys = sim_.system();
  require_static_memory(sys, first);
  chain_ = ExplicitChain::detect(sys);
  check_thread_deadline("(in the recognition of an open chain)");
  reduced_ = std::make_unique<ReducedSystem>(sys, sim_.data());
  check_thread_deadline("(in the set-up of the tangent stiffness)");
  x0_ = sim_.data().x;
}

StaticSolver::~StaticSolver() = default;

void StaticSolver::solve(StaticResults& res, const StaticOptions& opt, const Eigen::VectorXd* force) {
  const Clock::time_point start = Clock::now();
  check_options(opt);
  const DeadlineScope deadline(opt.time_limit);
  run(res, opt, force, start);
}

void StaticSolver::run(StaticResults& res, const StaticOptions& opt, const Eigen::VectorXd* force,
                       Clock::time_point start) {
  res = StaticResults();
  const System& sys = sim_.system();
  Data& data = sim_.data();
  if (force && force->size() != sys.nx)
    throw InputError("static: the loads must have one value per nodal coordinate (" + std::to_string(sys.nx) +
                     "), got " + std::to_string(force->size()));
  if (force && !force->allFinite()) throw InputError("static: the loads must be finite numbers");
  res.warnings = sys.warnings;
  res.coord_label = sys.coord_label;
  res.def_label = sys.def_label;
  res.x_dyn = sys.x_dyn;
  res.e_dyn = sys.e_dyn;
  const int n = result_rows(opt);
  require_static_memory(sys, &opt);
  if (!fresh_) {  // the state of a solve before: back to the model's
    data.reset_state(sys);
    data.x = x0_;
    reduced_->forget_pivots();
  }
  fresh_ = false;
  sim_.assemble(chain_.get());
  if (force) data.constant_load = *force;  // in place of FORCE, scaled by λ with it (compute_inertia_and_loads)
  data.t = sys.t0;
  EquilibriumPath path(sys, data, opt, res, *reduced_, chain_.get());
  path.start();
  Rows rows(sys, data, path, res, n);
  try {
    if (opt.arc_length)
      follow_arc_length(sys, path, opt, res, rows);
    else
      follow_load_steps(sys, path, opt, res, rows);
  } catch (const Error&) {
    rows.finish();
    res.wall_time = std::chrono::duration<double>(Clock::now() - start).count();
    throw;
  }
  rows.finish();
  res.wall_time = std::chrono::duration<double>(Clock::now() - start).count();
}

void solve_static(Model& model, StaticResults& res, const StaticOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  check_options(opt);
  const DeadlineScope deadline(opt.time_limit);  // the set-up included
  res = StaticResults();
  StaticSolver solver(model, &opt);  // the memory of the rows checked before the set-up
  solver.run(res, opt, nullptr, start);
  solver.store_state();
}

}  // namespace spacar
