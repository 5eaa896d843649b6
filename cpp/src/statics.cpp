#include "spacar/statics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "spacar/dynamics.hpp"
#include "spacar/kinematics.hpp"
#include "spacar/limits.hpp"

namespace spacar {

namespace {

// Σ_k B_kᵀ σ_k over all deformations, added to out.
void add_stress_loads(const System& sys, const Data& data, Eigen::VectorXd& out) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const ElementWork& w = data.work[i];
    for (int a = 0; a < se.nd; ++a) {
      const double s = data.sigma[se.def_offset + a];
      if (s == 0.0) continue;
      for (size_t j = 0; j < se.coords.size(); ++j) out[se.coords[j]] += w.B(a, j) * s;
    }
  }
}

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

}  // namespace

std::string dof_name(const System& sys, int j) {
  const int nxd = static_cast<int>(sys.x_dyn.size());
  if (j < nxd) return "DYNX " + sys.coord_name(sys.x_dyn[j]);
  return "DYNE " + sys.def_name(sys.e_dyn[j - nxd]);
}

double static_forces(const System& sys, Data& data, double lambda, Eigen::VectorXd& R, Eigen::MatrixXd* K,
                     Eigen::VectorXd* dR_dlambda, const Eigen::VectorXd* input_rate) {
  const int nd = sys.n_dof();
  // At rest: no rates, no accelerations, hence no inertia or convective forces.
  data.qhat_d.setZero();
  data.qhat_dd.setZero();
  solve_transfer(sys, data);
  solve_velocities(sys, data);
  data.xdd.setZero();
  data.edd.setZero();
  compute_inertia_and_loads(sys, data);
  Eigen::VectorXd full_load;
  if (dR_dlambda) full_load = data.f;
  data.f *= lambda;
  constitutive_stresses(sys, data);
  // The unbalanced load w = −λf + Σ Bᵀσ on every coordinate; R = DF_qᵀ w.
  Eigen::VectorXd w = Eigen::VectorXd::Zero(sys.nx);
  add_stress_loads(sys, data, w);
  double scale = 0.0;  // the largest applied or elastic load on a coordinate, in units of energy
  for (int g = 0; g < sys.nx; ++g) {
    const double size = sys.coord_is_length[g] ? sys.length_scale : 1.0;
    scale = std::max(scale, std::max(std::abs(w[g]), std::abs(data.f[g])) * size);
  }
  w -= data.f;
  for (int j = 0; j < nd; ++j) data.DFq.col(j) = data.DF.col(sys.dof_cols[j]);
  R.noalias() = data.DFq.transpose() * w;
  if (dR_dlambda) dR_dlambda->noalias() = -data.DFq.transpose() * full_load;
  // Reaction stresses of the velocity rows from the equilibrium of the calculable coordinates,
  // A_Vᵀ y = −w_c (formulation.md §6); on DOF deformation rows y → 0 at equilibrium. With them
  // Σ σ_k H_k is exactly the derivative of DF_q (the second-order transfer) contracted with w.
  const int nc = static_cast<int>(sys.x_calc.size());
  if (nc > 0) {
    Eigen::VectorXd rhs(nc), y(nc);
    for (int j = 0; j < nc; ++j) rhs[j] = -w[sys.x_calc[j]];
    data.luV.solve_transposed(rhs, y);
    for (int r = 0; r < nc; ++r) data.sigma[sys.defs_V[r]] += y[r];
  }
  data.reaction = -data.f;
  add_stress_loads(sys, data, data.reaction);
  for (int g = 0; g < sys.nx; ++g) {
    const CoordClass c = sys.coord_class[g];
    if (c != CoordClass::Fixed && c != CoordClass::Input) data.reaction[g] = 0.0;
  }
  if (!K) return scale;
  // Tangent stiffness K0 + G0: G0 with the complete stresses and the stiffness of the
  // position-dependent loads (beam gravity, TORQUEL), which scale with λ.
  Eigen::MatrixXd Kx = geometric_stiffness(sys, data, data.sigma);
  if (lambda != 1.0 && (sys.gravity.squaredNorm() > 0.0 || !sys.torquel.empty()))
    Kx -= (1.0 - lambda) * geometric_stiffness(sys, data, Eigen::VectorXd::Zero(sys.ne));
  Eigen::MatrixXd DFeq(sys.ne, nd);
  for (int j = 0; j < nd; ++j) DFeq.col(j) = data.DFe.col(sys.dof_cols[j]);
  const Eigen::MatrixXd S = global_constitutive(sys, false);
  *K = congruence(data.DFq, Kx) + congruence(DFeq, S);   // G0 + K0
  if (dR_dlambda && input_rate && input_rate->size() > 0) {
    // The same tangent in the direction of the inputs' motion: the inputs are further columns
    // of q̂, and Σ σ_k H_k with the complete stresses differentiates DF_q along them too.
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(sys.nx), de = Eigen::VectorXd::Zero(sys.ne);
    for (int i = 0; i < sys.n_input(); ++i) {
      dx.noalias() += (*input_rate)[i] * data.DF.col(sys.input_cols[i]);
      de.noalias() += (*input_rate)[i] * data.DFe.col(sys.input_cols[i]);
    }
    dR_dlambda->noalias() += data.DFq.transpose() * (Kx * dx) + DFeq.transpose() * (S * de);
  }
  return scale;
}

namespace {

// Newton's iterations for one load factor from the current state, and the state to go back to.
class EquilibriumPath {
 public:
  EquilibriumPath(const System& sys, Data& data, const StaticOptions& opt, StaticResults& res)
      : sys_(sys), data_(data), opt_(opt), res_(res), nd_(sys.n_dof()) {
    scale_.resize(nd_);
    int j = 0;
    for (int g : sys.x_dyn) scale_[j++] = sys.coord_is_length[g] ? sys.length_scale : 1.0;
    for (int k : sys.e_dyn) scale_[j++] = sys.def_is_length[k] ? sys.length_scale : 1.0;
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
  void start() {
    static_forces(sys_, data_, 0.0, R0_, nullptr);
    have_DF_ = true;
  }

  // Equilibrium at load factor λ, starting from the current state. The sign of det K must stay
  // that of the start: a change during the iterations means that the step crosses a limit or
  // bifurcation point, and Newton may land on a distant branch (a snap-through). Such a step
  // fails unless `last_chance` (the smallest step): then an end beyond a bifurcation, where the
  // sign has changed, is accepted (an unstable equilibrium, reported as indefinite), while a
  // return to the start's sign (the jump past a limit point) fails.
  Attempt solve(double lambda, bool last_chance) {
    Attempt a;
    Eigen::VectorXd qhat = with_inputs(data_.qhat, lambda);
    Eigen::VectorXd R;
    double last_correction = std::numeric_limits<double>::infinity();
    int start_sign = 0;
    bool crossed = false;
    for (int it = 0;; ++it) {
      check_thread_deadline("(in the static analysis)");
      try {
        place(qhat);
      } catch (const KinematicsError& err) {
        a.why = std::string("the kinematics has no solution there (") + err.what() + ")";
        return a;
      }
      const double force = static_forces(sys_, data_, lambda, R, &K_);
      R -= (1.0 - lambda) * R0_;
      const Eigen::VectorXd Rs = scale_.cwiseProduct(R);
      if (!Rs.allFinite() || !K_.allFinite()) {
        a.why = "the forces or the stiffness are not finite";
        return a;
      }
      check_thread_deadline("(in the static analysis)");  // the dense decompositions cannot be interrupted
      const Eigen::MatrixXd Ks = scale_.asDiagonal() * K_ * scale_.asDiagonal();
      const Eigen::PartialPivLU<Eigen::MatrixXd> lu(Ks);
      // A tiny pivot: the stiffness may be singular; full pivoting confirms it and finds the null
      // directions.
      Eigen::MatrixXd null_space;
      const Eigen::VectorXd pivots = lu.matrixLU().diagonal().cwiseAbs();
      if (nd_ > 0 && !(pivots.minCoeff() > 1e-13 * pivots.maxCoeff())) {
        Eigen::FullPivLU<Eigen::MatrixXd> full(Ks);
        full.setThreshold(1e-13);
        if (!full.isInvertible()) null_space = full.kernel();
      }
      const bool singular = null_space.cols() > 0;
      const int sign = singular || nd_ == 0 ? 0 : determinant_sign(lu);
      if (it == 0) start_sign = sign;
      else if (sign != start_sign) crossed = true;
      if (crossed && !last_chance) {
        a.why = "the tangent stiffness changes the sign of its determinant within the step (a limit or "
                "bifurcation point)";
        return a;
      }
      double res_max = 0.0;
      Eigen::VectorXd dy;
      if (nd_ > 0) {
        res_max = Rs.cwiseAbs().maxCoeff(&a.worst);
        a.worst_residual = R[a.worst];
        if (!singular) dy = lu.solve(-Rs);
      }
      // Converged: the residual is small against the forces it balances; or it would move the
      // DOFs by less than round-off (nothing is loaded: a mechanism moved by its inputs); or the
      // corrections have reached round-off with a residual near it.
      const double correction = dy.size() ? dy.cwiseAbs().maxCoeff() : 0.0;
      if (res_max <= opt_.tolerance * force || (!singular && correction <= 1e-13) ||
          (last_correction <= 1e-12 && res_max <= 1e-6 * force)) {
        if (crossed && sign == start_sign) {
          a.why = "past a limit point: the only equilibrium found lies on a distant branch (a snap-through)";
          return a;
        }
        a.converged = true;
        return a;
      }
      if (it == opt_.max_iterations) {
        a.why = "Newton's method did not converge in " + std::to_string(opt_.max_iterations) + " iterations";
        return a;
      }
      if (singular) {
        a.why = "the tangent stiffness is singular: no stiffness in " + directions(null_space);
        a.singular_at_start = it == 0;
        return a;
      }
      ++a.iterations;
      ++res_.newton_iterations;
      last_correction = correction;
      for (int j = 0; j < nd_; ++j) qhat[sys_.dof_cols[j]] += scale_[j] * dy[j];
    }
  }

  // The scaled tangent stiffness of the last evaluation has an eigenvalue with a negative real
  // part: the equilibrium is unstable (for a symmetric stiffness, i.e. conservative loads: not
  // positive definite). Follower loads (TORQUEL) make it unsymmetric; its symmetric part may then
  // be indefinite at a stable equilibrium, so the eigenvalues of the matrix itself decide.
  // Returns "" or the description of the direction of the most negative eigenvalue.
  std::string indefinite() const {
    if (nd_ == 0) return "";
    check_thread_deadline("(in the static analysis)");
    const Eigen::MatrixXd Ks = scale_.asDiagonal() * K_ * scale_.asDiagonal();
    const double big = Ks.cwiseAbs().maxCoeff();
    double lowest = 0.0;
    Eigen::VectorXd direction;
    if ((Ks - Ks.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * big) {
      const Eigen::MatrixXd sym = 0.5 * (Ks + Ks.transpose());
      // Eigenvalues only at every step; the vector once an equilibrium is unstable.
      lowest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(sym, Eigen::EigenvaluesOnly).eigenvalues()[0];
      if (!(lowest < -1e-9 * big)) return "";
      direction = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(sym).eigenvectors().col(0);
    } else {
      Eigen::EigenSolver<Eigen::MatrixXd> eig(Ks);
      Eigen::Index k = 0;
      lowest = eig.eigenvalues().real().minCoeff(&k);
      direction = eig.eigenvectors().col(k).cwiseAbs();
    }
    if (!(lowest < -1e-9 * big)) return "";
    return directions(direction) + " (eigenvalue " + num(lowest / big) + " of the largest entry)";
  }

  // For the arc-length method: the state with the DOFs (and inputs) at q̂, at load factor λ:
  // the scaled residual of the path Fs = S (R − (1 − λ) R0), its derivative in λ at fixed q,
  // gs = S (−DF_qᵀ f + R0), and the tangent (scaled_tangent()). Returns the force scale.
  double evaluate(const Eigen::VectorXd& qhat, double lambda, Eigen::VectorXd& Fs, Eigen::VectorXd& gs) {
    place(with_inputs(qhat, lambda));
    Eigen::VectorXd R, g;
    const Eigen::VectorXd rate = p1_ - p0_;
    const double force = static_forces(sys_, data_, lambda, R, &K_, &g, &rate);
    R -= (1.0 - lambda) * R0_;
    g += R0_;
    Fs = scale_.cwiseProduct(R);
    gs = scale_.cwiseProduct(g);
    return force;
  }
  Eigen::MatrixXd scaled_tangent() const { return scale_.asDiagonal() * K_ * scale_.asDiagonal(); }
  const Eigen::VectorXd& scale() const { return scale_; }
  std::string dof_directions(const Eigen::VectorXd& v) const { return directions(v); }

  struct Snapshot {
    Eigen::VectorXd x, qhat, angle_ref;
    Eigen::MatrixXd DF;
    bool have_DF = false;
  };
  Snapshot save() const { return {data_.x, data_.qhat, data_.angle_ref, data_.DF, have_DF_}; }
  void restore(const Snapshot& s) {
    data_.x = s.x;
    data_.qhat = s.qhat;
    data_.angle_ref = s.angle_ref;
    data_.DF = s.DF;
    have_DF_ = s.have_DF;
  }

 private:
  // q̂ with the inputs at their values for load factor λ (moved linearly from p0 to p1).
  Eigen::VectorXd with_inputs(Eigen::VectorXd qhat, double lambda) const {
    for (int i = 0; i < sys_.n_input(); ++i) qhat[sys_.input_cols[i]] = p0_[i] + lambda * (p1_[i] - p0_[i]);
    return qhat;
  }

  // Positions for q̂: the calculable coordinates predicted along DF from the last state, then
  // solved by Newton on the constraints.
  void place(const Eigen::VectorXd& qhat) {
    if (have_DF_) data_.x.noalias() += data_.DF * (qhat - data_.qhat);
    data_.qhat = qhat;
    for (int g : sys_.x_input) data_.x[g] = qhat[sys_.qhat_col_x[g]];
    for (int g : sys_.x_dyn) data_.x[g] = qhat[sys_.qhat_col_x[g]];
    have_DF_ = false;  // until static_forces has evaluated it here
    // Full Newton on the positions: the steps between static iterates are large, and the chord
    // iteration with the last velocity block (meant for small time steps) would crawl.
    data_.jacobian_reusable = false;
    solve_positions(sys_, data_, std::max(sys_.settings.maxiterat, 50), std::min(sys_.settings.epskin, 1e-10), false);
    res_.kinematic_iterations += data_.newton_iterations;
    have_DF_ = true;   // static_forces follows at once
  }

  // The DOFs that make up the directions V (columns) of q: components ≥ 10% of the largest,
  // the largest first, at most four named.
  std::string directions(const Eigen::MatrixXd& V) const {
    std::vector<std::pair<double, int>> part;
    for (int j = 0; j < nd_; ++j) {
      double w = 0.0;
      for (int c = 0; c < V.cols(); ++c) w = std::max(w, std::abs(V(j, c)) / V.col(c).cwiseAbs().maxCoeff());
      if (w >= 0.1) part.push_back({-w, j});
    }
    std::sort(part.begin(), part.end());
    std::ostringstream os;
    os << "the direction of";
    for (size_t i = 0; i < part.size() && i < 4; ++i) os << (i ? ", " : " ") << dof_name(sys_, part[i].second);
    if (part.size() > 4) os << " and " << part.size() - 4 << " more";
    return os.str();
  }

  static int determinant_sign(const Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
    int sign = static_cast<int>(lu.permutationP().determinant());
    for (int i = 0; i < lu.matrixLU().rows(); ++i)
      if (lu.matrixLU()(i, i) < 0.0) sign = -sign;
    return sign;
  }

  const System& sys_;
  Data& data_;
  const StaticOptions& opt_;
  StaticResults& res_;
  const int nd_;
  Eigen::VectorXd scale_;        // characteristic size of each DOF: lengths vs angles
  Eigen::VectorXd p0_, p1_;
  Eigen::VectorXd R0_;           // generalized forces at the start (see start())
  Eigen::MatrixXd K_;
  bool have_DF_ = false;
};

// Riks' normal-plane arc-length method on y = (q_s, μ), q_s the DOFs divided by their scale
// and μ = c λ, c the size of dq_s/dλ at the start (so that a first step weighs displacement and
// load alike). Each step predicts along the unit tangent τ of the last point and corrects by
// Newton on the residual bordered with τᵀ (y − y_predicted) = 0: the bordered matrix stays
// regular at limit points, where K alone is singular. The tangent at a new point solves the
// same bordered system with the previous tangent, τ_oldᵀ τ > 0: the path goes on in the
// direction it came from, λ falling after a limit point. The step length follows the Newton
// iterations; a failed step is halved.
class ArcLength {
 public:
  ArcLength(const System& sys, EquilibriumPath& path, const StaticOptions& opt, StaticResults& res)
      : sys_(sys), path_(path), opt_(opt), res_(res), nd_(sys.n_dof()) {}

  struct Point {
    EquilibriumPath::Snapshot state;
    double lambda = 0.0;
    Eigen::VectorXd tau;  // unit tangent in y
  };

  // The starting point (the current state at λ = 0), its tangent, c and the first step length
  // (the one that raises λ by 1/steps along the tangent).
  Point start(const Eigen::VectorXd& qhat) {
    Point p;
    Eigen::VectorXd Fs;
    path_.evaluate(qhat, 0.0, Fs, gs_);
    check_thread_deadline("(in the static analysis)");
    const Eigen::MatrixXd Ks = path_.scaled_tangent();
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Ks);
    lu.setThreshold(1e-13);
    if (nd_ > 0 && !lu.isInvertible())
      throw StaticError("arc-length continuation needs a regular tangent stiffness at the start; it is singular in " +
                        path_.dof_directions(lu.kernel().col(0)));
    c_ = nd_ > 0 ? lu.solve(-gs_).norm() : 0.0;
    if (!(c_ > 0.0) || !std::isfinite(c_)) c_ = 1.0;  // nothing loaded: λ alone
    Eigen::VectorXd e = Eigen::VectorXd::Zero(nd_ + 1);
    e[nd_] = 1.0;
    p.state = path_.save();
    p.tau = tangent(e);
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
    Step s = correct(qhat, lambda, a.tau);
    if (!s.converged) return s;
    b.state = path_.save();
    b.lambda = lambda;
    b.tau = tangent(a.tau);
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
  // Newton on [F(q, λ); nᵀ (y − y0)] = 0 from y0 = (q̂, λ).
  Step correct(Eigen::VectorXd qhat, double& lambda, const Eigen::VectorXd& n) {
    Step s;
    const Eigen::VectorXd& scale = path_.scale();
    Eigen::VectorXd Fs;
    double last_correction = std::numeric_limits<double>::infinity();
    for (int it = 0;; ++it) {
      check_thread_deadline("(in the static analysis)");
      double force = 0.0;
      try {
        force = path_.evaluate(qhat, lambda, Fs, gs_);
      } catch (const KinematicsError& err) {
        s.why = std::string("the kinematics has no solution there (") + err.what() + ")";
        return s;
      }
      if (!Fs.allFinite() || !gs_.allFinite()) {
        s.why = "the forces or the stiffness are not finite";
        return s;
      }
      double res_max = 0.0;
      if (nd_ > 0) {
        res_max = Fs.cwiseAbs().maxCoeff(&s.worst);
        s.worst_residual = Fs[s.worst] / scale[s.worst];
      }
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nd_ + 1);
      rhs.head(nd_) = -Fs;
      const Eigen::VectorXd dy = bordered(n).partialPivLu().solve(rhs);
      if (!dy.allFinite()) {
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

  // [K_s, g_s / c; nᵀ] at the last evaluation.
  Eigen::MatrixXd bordered(const Eigen::VectorXd& n) const {
    Eigen::MatrixXd J(nd_ + 1, nd_ + 1);
    J.topLeftCorner(nd_, nd_) = path_.scaled_tangent();
    J.topRightCorner(nd_, 1) = gs_ / c_;
    J.row(nd_) = n.transpose();
    return J;
  }

  // The unit tangent at the last evaluation, oriented by nᵀ τ > 0.
  Eigen::VectorXd tangent(const Eigen::VectorXd& n) const {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(nd_ + 1);
    e[nd_] = 1.0;
    const Eigen::VectorXd t = bordered(n).partialPivLu().solve(e);
    return t / t.norm();
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
    throw InputError("static: the tolerance must be between 0 and 1, got " + num(o.tolerance));
  if (o.max_steps < 1)
    throw InputError("static: max_steps must be at least 1, got " + std::to_string(o.max_steps));
  if (!(o.time_limit >= 0.0)) throw InputError("static: the time limit must not be negative, got " + num(o.time_limit));
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
    res_.warnings.push_back("the tangent stiffness is indefinite at load factor " + num(lambda) + " in " + dir +
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
    const EquilibriumPath::Attempt a = path.solve(next, last_chance);
    iterations += a.iterations;
    if (!a.converged) {
      const bool hopeless = a.singular_at_start || last_chance;
      if (hopeless) {
        std::ostringstream os;
        os << "no static equilibrium found beyond load factor " << num(lambda) << " (of 1; tried " << num(next)
           << "): " << a.why;
        if (a.worst >= 0) os << "; worst residual " << num(a.worst_residual) << " on " << dof_name(sys, a.worst);
        if (!a.singular_at_start) {
          os << " (load step cut " << res.step_cuts << " times, down to " << num(step)
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
        os << "the arc-length method failed beyond load factor " << num(a.lambda) << ": " << s.why;
        if (s.worst >= 0) os << "; worst residual " << num(s.worst_residual) << " on " << dof_name(sys, s.worst);
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
      res.warnings.push_back("limit point at load factor " + num(limit) +
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
        path.evaluate(qhat, 1.0, Fs, gs);
        last = path.solve(1.0, true);
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
        throw StaticError("the arc-length method passed load factor 1 after " + num(a.lambda) +
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
      path.evaluate(b.state.qhat, b.lambda, Fs, gs);
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
     << num(a.lambda) << " reached";
  if (!res.limit_points.empty()) {
    os << " after limit points at";
    for (double l : res.limit_points) os << " " << num(l);
  }
  os << ". Allow more steps (max_steps) or longer ones (fewer steps)";
  throw StaticError(os.str());
}

}  // namespace

void solve_static(Model& model, StaticResults& res, const StaticOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  check_options(opt);
  const DeadlineScope deadline(opt.time_limit);  // the set-up included
  res = StaticResults();
  Simulation sim(model);
  const System& sys = sim.system();
  Data& data = sim.data();
  res.warnings = sys.warnings;
  res.coord_label = sys.coord_label;
  res.def_label = sys.def_label;
  res.x_dyn = sys.x_dyn;
  res.e_dyn = sys.e_dyn;
  const int n = opt.arc_length ? opt.max_steps + 1 : opt.steps;  // arc length: the last row at λ = 1
  require_memory(Data::estimate_dense_bytes(sys) + 8.0 * n * (2.0 * sys.nx + 2.0 * sys.ne + 2.0),
                 "the static analysis of " + std::to_string(sys.nx) + " nodal coordinates and " +
                     std::to_string(sys.ne) + " deformations in " + std::to_string(n) + " load steps",
                 opt.arc_length ? "allow fewer steps (max_steps)" : "use fewer load steps");
  sim.assemble();
  data.t = sys.t0;
  EquilibriumPath path(sys, data, opt, res);
  path.start();
  Rows rows(sys, data, path, res, n);
  try {
    if (opt.arc_length)
      follow_arc_length(sys, path, opt, res, rows);
    else
      follow_load_steps(sys, path, opt, res, rows);
  } catch (const Error&) {
    rows.finish();
    res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    throw;
  }
  rows.finish();
  res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sim.store_state();
}

StaticTangent static_tangent(Model& model, double load_factor, const Eigen::VectorXd* x, const Eigen::VectorXd* e) {
  Simulation sim(model);
  sim.assemble();
  const System& sys = sim.system();
  Data& data = sim.data();
  if (x || e) {
    if (!x || !e || x->size() != sys.nx || e->size() != sys.ne)
      throw InputError("static_tangent: x and e must both be given, with " + std::to_string(sys.nx) + " and " +
                       std::to_string(sys.ne) + " values");
    // The row is a solved state: its positions, and the independent coordinates from them; the
    // kinematics then only refreshes the deformations and their derivatives there.
    data.x = *x;
    for (int g = 0; g < sys.nx; ++g)
      if (sys.qhat_col_x[g] >= 0) data.qhat[sys.qhat_col_x[g]] = (*x)[g];
    for (int k = 0; k < sys.ne; ++k)
      if (sys.qhat_col_e[k] >= 0) data.qhat[sys.qhat_col_e[k]] = (*e)[k];
    data.jacobian_reusable = false;
    solve_positions(sys, data, std::max(sys.settings.maxiterat, 50), std::min(sys.settings.epskin, 1e-10), false);
  }
  StaticTangent t;
  static_forces(sys, data, load_factor, t.R, &t.K);
  t.DF = Eigen::MatrixXd(data.DFq);
  t.x = data.x;
  t.coord_label = sys.coord_label;
  for (int j = 0; j < sys.n_dof(); ++j) t.dof_names.push_back(dof_name(sys, j));
  return t;
}

}  // namespace spacar
