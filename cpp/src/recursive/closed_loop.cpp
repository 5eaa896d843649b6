// Closed loops on the recursive path (closed_loop.hpp): the loops' constraints on a planar or a
// spatial tree, closed by Newton's method in the passive joints, and the equations of motion in
// the DOFs.
#include "spacar/recursive/closed_loop.hpp"

#include <algorithm>
#include <cmath>

#include "spacar/autodiff.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"
#include "spacar/recursive/planar_rnea.hpp"
#include "spacar/recursive/planar_tree.hpp"
#include "spacar/recursive/spatial_rnea.hpp"
#include "spacar/recursive/spatial_tree.hpp"

namespace spacar {

namespace {

constexpr int kMaxIterations = 30;
// Newton's method stops at residuals of 1e-14 (points: of the tree's size; times 1 + the largest
// coordinate), near round-off: at 1e-12 the accelerations were off by 1e-11 (relative); or at a
// correction at round-off if the residual is below 1e-10 (else the constraints have no solution
// there: a least-squares minimum).
constexpr double kResidual = 1e-14, kRoundOff = 1e-15, kStalled = 1e-10;
// Continuation (continue_to): pieces that move no coordinate by more than 0.1, Newton's
// correction of a piece's predicted start at most a quarter of its move (plus 1e-12: the same
// state again), pieces down to 1e-14 of the path, at most 20 000 of them (a jump of 300 rad takes
// 3000, some milliseconds).
constexpr double kMaxMove = 0.1, kCorrection = 0.25, kSameState = 1e-12, kMinPiece = 1e-14;
constexpr int kMaxAttempts = 20000;

using Cut = TreeLoops<Eigen::Vector3d>::Cut;  // spatial

// The Euler parameters of a LAMBDA node on a body (body < 0: the ground) from its parameters at
// the recognition.
Eigen::Vector4d node_lambda(const Cut& cut, int end, const Eigen::Vector4d& body_lambda) {
  return cut.body[end] < 0 ? cut.lambda0[end] : tree_detail::compose(body_lambda, cut.lambda0[end]);
}

}  // namespace

void DependentJoints::resize(int m, int n) {
  m_ = m;
  n_ = n;
  lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  qr_ = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(m, n);
}

bool DependentJoints::compute(const Eigen::Ref<const Eigen::MatrixXd>& Jd) {
  // Below this ratio of the smallest to the largest pivot the QR decides (its rank threshold
  // lies far below it). The ratio, not Eigen's rcond(): its estimate cost more than the LU.
  constexpr double kNearSingular = 1e-10;
  if (m_ == n_) {
    lu_.compute(Jd);
    const auto pivots = lu_.matrixLU().diagonal().cwiseAbs();
    lu_used_ = n_ > 0 && pivots.allFinite() && pivots.minCoeff() > kNearSingular * pivots.maxCoeff();
    if (lu_used_) return true;
  }
  lu_used_ = false;
  qr_.compute(Jd);
  return qr_.rank() == n_;
}

void DependentJoints::solve(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::Ref<Eigen::MatrixXd> x) const {
  if (lu_used_)
    x.noalias() = lu_.solve(b);
  else
    x.noalias() = qr_.solve(b);
}

template <class Algebra>
ClosedLoopTree<Algebra>::ClosedLoopTree(std::unique_ptr<Tree> tree) : tree_(std::move(tree)), loops_(tree_->loops()) {
  nd_ = loops_.n_dof;
  nn_ = static_cast<int>(loops_.dependent0.size());
  n_point_rows_ = m_ = Point::RowsAtCompileTime * static_cast<int>(loops_.points.size());
  for (const auto& cut : loops_.cuts) m_ += static_cast<int>(cut.rows.size());
  const int n = nd_ + nn_;
  theta_ = theta_d_ = theta_dd_ = zero_ = g_ = col_ = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < nn_; ++k) theta_[nd_ + k] = loops_.dependent0[k];
  c_ = gamma_ = Eigen::VectorXd::Zero(m_);
  q_last_ = rhs_ = Eigen::VectorXd::Zero(nd_);
  w_ = Eigen::VectorXd::Zero(n);
  start_ = step_ = predicted_ = tangent_move_ = Eigen::VectorXd::Zero(nn_);
  from_ = step_q_ = delta_ = Eigen::VectorXd::Zero(nd_);
  T_start_ = Eigen::MatrixXd::Zero(nn_, nd_);
  J_ = Eigen::MatrixXd::Zero(m_, n);
  T_ = MT_ = Eigen::MatrixXd::Zero(n, nd_);
  A_ = Eigen::MatrixXd::Zero(nd_, nd_);
  qr_.resize(m_, nn_);
  llt_ = Eigen::LLT<Eigen::MatrixXd>(nd_);
  T_.topRows(nd_).setIdentity();
  length_ = 0.0;
  for (const auto& body : tree_->bodies_) length_ += body.r.norm();
  for (const auto& p : loops_.points) length_ = std::max(length_, p.pa.norm());
  if (!(length_ > 0.0)) length_ = 1.0;
}

template <class Algebra>
std::unique_ptr<RecursiveTree> ClosedLoopTree<Algebra>::close(std::unique_ptr<Tree> tree, const System& sys,
                                                              const Data& data, std::string* why) {
  auto loop = std::unique_ptr<ClosedLoopTree>(new ClosedLoopTree(std::move(tree)));
  // The assembled state: q holds the DYNX coordinates (a planar body's rotation), then the DOF
  // joints' e1.
  const int nx = static_cast<int>(sys.x_dyn.size());
  for (int k = 0; k < loop->nd_; ++k)
    loop->q_last_[k] = loop->theta_[k] = k < nx ? data.x[sys.x_dyn[k]] : data.e[sys.e_dyn[k - nx]];
  // The tangent there (the first state's predictor).
  loop->tree_->outward(loop->theta_.data(), loop->zero_.data());
  loop->constraints();
  if (!loop->qr_.compute(loop->J_.rightCols(loop->nn_))) {
    if (why) {
      *why = "the loops do not determine their " + std::to_string(loop->nn_) + " passive joints (" +
             std::to_string(loop->m_) + " constraints of rank " + std::to_string(loop->qr_.rank()) + ")";
    }
    return nullptr;
  }
  loop->dependent_tangent();
  loop->q0_ = loop->q_last_;  // the recognized state: close_loops' second start
  loop->theta0_ = loop->theta_.tail(loop->nn_);
  loop->T0_ = loop->T_.bottomRows(loop->nn_);
  return loop;
}

// Points: c = x_a − x_b; a cut (spatial): its rigid misalignments (add_cut_rows).
template <class Algebra>
void ClosedLoopTree<Algebra>::constraints() {
  constexpr int d = Point::RowsAtCompileTime;
  J_.setZero();
  int row = 0;
  for (const auto& p : loops_.points) {
    const Point xa = world_point(p.a, p.pa), xb = world_point(p.b, p.pb);
    c_.template segment<d>(row) = xa - xb;
    add_point_rows(p.a, xa, 1.0, row);
    if (p.b >= 0) add_point_rows(p.b, xb, -1.0, row);
    row += d;
  }
  add_cut_rows(row);
}

// After the tree's accelerations at θ̈ = 0 without gravity.
template <class Algebra>
void ClosedLoopTree<Algebra>::constraint_bias() {
  constexpr int d = Point::RowsAtCompileTime;
  int row = 0;
  for (const auto& p : loops_.points) {
    gamma_.template segment<d>(row) = point_acceleration(p.a, p.pa);
    if (p.b >= 0) gamma_.template segment<d>(row) -= point_acceleration(p.b, p.pb);
    row += d;
  }
  add_cut_bias(row);
}

// --- spatial: ẋ = Σ (S_j θ̇_j) × (x − pin_j) over the joints on a body's path (a sliding joint's:
// its axis); a cut's rows e_k(λ_o1, λ_o2) − e_k(recognition), ∂e/∂θ_j = B ½ E(λ)ᵀ ω_j (λ̇ = ½ E(λ)ᵀ ω,
// world ω).

template <>
SpatialAlgebra::Point ClosedLoopTree<SpatialAlgebra>::world_point(int body, const Point& b) const {
  if (body < 0) return b;
  const auto& d = tree_->work_[body];
  return d.pin + d.frame.R * b;
}

template <>
void ClosedLoopTree<SpatialAlgebra>::add_point_rows(int body, const Point& p, double scale, int row) {
  for (int j = body; j >= 0; j = tree_->bodies_[j].parent) {
    const auto& m = tree_->bodies_[j];
    const auto& d = tree_->work_[j];
    const Eigen::Vector3d axis = d.frame.R * m.axis;
    const Eigen::Vector3d rate = m.prismatic ? axis : Eigen::Vector3d(axis.cross(p - d.pin));
    J_.block<3, 1>(row, m.dof) += scale * m.sign * rate;
  }
}

// R (a_v + α × b + ω × (v + ω × b)) from the body's motion (body coordinates).
template <>
SpatialAlgebra::Point ClosedLoopTree<SpatialAlgebra>::point_acceleration(int body, const Point& b) const {
  const auto& d = tree_->work_[body];
  const Eigen::Vector3d w = d.v.head<3>(), v = d.v.tail<3>() + w.cross(b);
  return d.frame.R * (d.a.tail<3>() + d.a.head<3>().cross(b) + w.cross(v));
}

template <>
void ClosedLoopTree<SpatialAlgebra>::add_rotation_row(int body, const Eigen::Matrix<double, 1, 3>& w, int row) {
  for (int j = body; j >= 0; j = tree_->bodies_[j].parent) {
    const auto& m = tree_->bodies_[j];
    if (!m.prismatic) J_(row, m.dof) += m.sign * w.dot(tree_->work_[j].frame.R * m.axis);
  }
}

template <>
void ClosedLoopTree<SpatialAlgebra>::add_cut_rows(int row) {
  const auto& work = tree_->work_;
  for (const Cut& cut : loops_.cuts) {
    Eigen::Matrix<double, 8, 1> x;
    Eigen::Vector3d e;
    Eigen::Matrix<double, 3, 8> B;
    std::array<Eigen::Vector4d, 2> l;
    for (int end = 0; end < 2; ++end) {
      l[end] = node_lambda(cut, end, cut.body[end] < 0 ? cut.lambda0[end] : work[cut.body[end]].frame.lambda);
      x.segment<4>(4 * end) = l[end];
    }
    cut.kernel->first_derivatives(x.data(), e.data(), B.data());
    for (size_t r = 0; r < cut.rows.size(); ++r, ++row) {
      c_[row] = e[cut.rows[r]] - cut.value[r];
      for (int end = 0; end < 2; ++end)
        if (cut.body[end] >= 0) {
          const Eigen::Matrix<double, 1, 3> w = 0.5 * B.block<1, 4>(cut.rows[r], 4 * end) * euler_E(l[end]).transpose();
          add_rotation_row(cut.body[end], w, row);
        }
    }
  }
}

// A cut's ë = B ẍ + c(x, ẋ) with λ̈ = ½ E(λ̇)ᵀ ω + ½ E(λ)ᵀ α (world ω, α).
template <>
void ClosedLoopTree<SpatialAlgebra>::add_cut_bias(int row) {
  const auto& work = tree_->work_;
  for (const Cut& cut : loops_.cuts) {
    Eigen::Matrix<double, 8, 1> x, xd = Eigen::Matrix<double, 8, 1>::Zero(), xdd = xd;
    Eigen::Vector3d e, conv;
    Eigen::Matrix<double, 3, 8> B;
    for (int end = 0; end < 2; ++end) {
      const int body = cut.body[end];
      const Eigen::Vector4d l = node_lambda(cut, end, body < 0 ? cut.lambda0[end] : work[body].frame.lambda);
      x.segment<4>(4 * end) = l;
      if (body < 0) continue;
      const auto& d = work[body];
      const Eigen::Vector3d w = d.frame.R * d.v.head<3>(), alpha = d.frame.R * d.a.head<3>();
      const Eigen::Vector4d ld = 0.5 * euler_E(l).transpose() * w;
      xd.segment<4>(4 * end) = ld;
      xdd.segment<4>(4 * end) = 0.5 * (euler_E(ld).transpose() * w + euler_E(l).transpose() * alpha);
    }
    cut.kernel->first_derivatives(x.data(), e.data(), B.data());
    cut.kernel->convective(x.data(), xd.data(), conv.data());
    for (size_t r = 0; r < cut.rows.size(); ++r, ++row) gamma_[row] = B.row(cut.rows[r]).dot(xdd) + conv[cut.rows[r]];
  }
}

// --- planar: ṗ = Σ ω_j ẑ × s_j over the bodies on p's path, s_j the segment of body j from its pin
// to the next body's pin (to p on p's own body), ω_j its absolute rate: θ̇ of its own rotation (an
// absolute joint) or ω_parent + sign θ̇ (a hinge). No cuts: a planar loop closes at points.

template <>
PlanarAlgebra::Point ClosedLoopTree<PlanarAlgebra>::world_point(int body, const Point& b) const {
  if (body < 0) return b;
  const auto& d = tree_->work_[body];
  const auto& f = d.frame;
  return d.pin + Point(f.cw * b.x() - f.sw * b.y(), f.sw * b.x() + f.cw * b.y());
}

template <>
void ClosedLoopTree<PlanarAlgebra>::add_point_rows(int body, const Point& p, double scale, int row) {
  path_.clear();
  for (int j = body; j >= 0; j = tree_->bodies_[j].parent) path_.push_back(j);
  w_.setZero();  // ∂ω_j/∂θ̇, from the root down
  for (int k = static_cast<int>(path_.size()) - 1; k >= 0; --k) {
    const int j = path_[k];
    const auto& m = tree_->bodies_[j];
    if (m.absolute) w_.setZero();
    w_[m.dof] += m.absolute ? 1.0 : m.sign;
    const Point s = (k == 0 ? p : tree_->work_[path_[k - 1]].pin) - tree_->work_[j].pin;
    J_.row(row) -= scale * s.y() * w_.transpose();
    J_.row(row + 1) += scale * s.x() * w_.transpose();
  }
}

// The point's acceleration from the body's motion (body coordinates), as move_coordinates.
template <>
PlanarAlgebra::Point ClosedLoopTree<PlanarAlgebra>::point_acceleration(int body, const Point& b) const {
  const auto& d = tree_->work_[body];
  const double w = d.v[0], wd = d.a[0];
  const double vx = d.v[1] - w * b.y(), vy = d.v[2] + w * b.x();
  const double ax = d.a[1] - wd * b.y() - w * vy, ay = d.a[2] + wd * b.x() + w * vx;
  return Point(d.frame.cw * ax - d.frame.sw * ay, d.frame.sw * ax + d.frame.cw * ay);
}

template <>
void ClosedLoopTree<PlanarAlgebra>::add_cut_rows(int) {}

template <>
void ClosedLoopTree<PlanarAlgebra>::add_cut_bias(int) {}

// By continuation from the last closed state, so that the loops stay on the assembly branch they
// are on (a loop closes in several ways: the other branch is a finite correction away); if that
// fails (from a state next to a fold, where the tangent is steep), from the recognized state.
template <class Algebra>
bool ClosedLoopTree<Algebra>::close_loops(const double* q) {
  start_ = theta_.tail(nn_);
  from_ = q_last_;
  T_start_ = T_.bottomRows(nn_);
  for (const bool recognized : {false, true}) {
    if (recognized) {
      theta_.tail(nn_) = theta0_;
      q_last_ = q0_;
      T_.bottomRows(nn_) = T0_;
    }
    if (continue_to(q)) {
      for (int k = 0; k < nd_; ++k) q_last_[k] = q[k];
      return true;
    }
  }
  theta_.tail(nn_) = start_;
  q_last_ = from_;
  T_.bottomRows(nn_) = T_start_;
  return false;
}

// Along the straight path from q_last to q in pieces, each started from the last piece's state
// moved along its tangent, θ_d + T_d Δq (second order in Δq: an integrator's stages, a piece apart,
// converge in one or two iterations) and accepted only if Newton's correction of that start is at
// most kCorrection of the move; a piece moves no coordinate by more than kMaxMove, doubles after
// an accepted piece and quarters after a rejected one (down to kMinPiece of the path: a fold).
template <class Algebra>
bool ClosedLoopTree<Algebra>::continue_to(const double* q) {
  for (int k = 0; k < nd_; ++k) step_q_[k] = q[k] - q_last_[k];
  if (!step_q_.allFinite()) return false;
  accepted_ = theta_.tail(nn_);
  double done = 0.0, piece = 1.0;
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    tangent_move_.noalias() = T_.bottomRows(nn_) * step_q_;
    const double steep = std::max(step_q_.cwiseAbs().maxCoeff(), tangent_move_.cwiseAbs().maxCoeff());
    if (steep > 0.0) piece = std::min(piece, kMaxMove / steep);
    const bool last = piece >= 1.0 - done;
    const double to = last ? 1.0 : done + piece;
    delta_ = step_q_ * (to - done);
    predicted_.noalias() = T_.bottomRows(nn_) * delta_;  // the move, then the start
    const double moved = std::max(delta_.cwiseAbs().maxCoeff(), predicted_.cwiseAbs().maxCoeff());
    predicted_ += accepted_;
    for (int k = 0; k < nd_; ++k) theta_[k] = last ? q[k] : q_last_[k] + step_q_[k] * to;
    theta_.tail(nn_) = predicted_;
    if (newton() && (theta_.tail(nn_) - predicted_).cwiseAbs().maxCoeff() <= kCorrection * moved + kSameState) {
      if (last) return true;
      done = to;
      accepted_ = theta_.tail(nn_);
      dependent_tangent();  // the next piece's
      piece *= 2.0;
    } else {
      theta_.tail(nn_) = accepted_;
      piece *= 0.25;
      if (piece < kMinPiece) return false;
    }
  }
  return false;
}

template <class Algebra>
bool ClosedLoopTree<Algebra>::newton() {
  for (int it = 0; it < kMaxIterations; ++it) {
    tree_->place(theta_.data(), zero_.data());
    constraints();
    if (!c_.allFinite() || !qr_.compute(J_.rightCols(nn_))) return false;  // (std::max below drops NaNs)
    double residual = 0.0;
    for (int r = 0; r < m_; ++r) residual = std::max(residual, std::abs(c_[r]) / (r < n_point_rows_ ? length_ : 1.0));
    // The coordinates' own round-off: a crank 300 rad round holds its angle to 3e-14.
    const double scale = 1.0 + theta_.cwiseAbs().maxCoeff();
    if (residual <= kResidual * scale) return true;
    qr_.solve(c_, step_);
    theta_.tail(nn_) -= step_;
    if (step_.cwiseAbs().maxCoeff() <= kRoundOff * scale) {
      tree_->place(theta_.data(), zero_.data());  // the tree placed at θ, as after every other return
      return residual <= kStalled * scale;
    }
  }
  return false;
}

template <class Algebra>
void ClosedLoopTree<Algebra>::dependent_tangent() {
  qr_.solve(J_.leftCols(nd_), T_.bottomRows(nn_));
  T_.bottomRows(nn_) = -T_.bottomRows(nn_);
}

template <class Algebra>
bool ClosedLoopTree<Algebra>::prepare(const double* q, const double* qd) {
  if (!close_loops(q)) return false;
  dependent_tangent();
  const Eigen::Map<const Eigen::VectorXd> rates(qd, nd_);
  theta_d_.head(nd_) = rates;
  theta_d_.tail(nn_).noalias() = T_.bottomRows(nn_) * rates;
  tree_->outward(theta_.data(), theta_d_.data(), true);  // placed at θ by close_loops()
  tree_->applied_loads();
  tree_->accelerate(theta_.data(), theta_d_.data(), zero_.data(), Tree::Vector::Zero(), true);
  constraint_bias();
  qr_.solve(gamma_, g_.tail(nn_));
  g_.tail(nn_) = -g_.tail(nn_);
  return true;
}

template <class Algebra>
bool ClosedLoopTree<Algebra>::solve(const double* q, const double* qd, double* qdd) {
  if (!prepare(q, qd)) return false;
  Tree& tree = *tree_;
  // τ_id(θ, θ̇, g): the forces of the accelerations g, the bias forces and the loads.
  tree.forces(theta_.data(), theta_d_.data(), g_.data(), col_.data());
  rhs_.noalias() = -T_.transpose() * col_;
  for (int k = 0; k < nd_; ++k) tree.mass_times(T_.col(k).data(), MT_.col(k).data());
  A_.noalias() = T_.transpose() * MT_;
  llt_.compute(A_);
  if (llt_.info() != Eigen::Success) return false;
  Eigen::Map<Eigen::VectorXd> out(qdd, nd_);
  out = llt_.solve(rhs_);
  theta_dd_.noalias() = T_ * out;  // the bodies' accelerations from it in move_coordinates()
  theta_dd_ += g_;
  return out.allFinite();
}

template <class Algebra>
void ClosedLoopTree<Algebra>::inverse_dynamics(const double* q, const double* qd, const double* qdd, double* force) {
  if (!prepare(q, qd))
    throw InputError("inverse_dynamics: the loops do not close at this state (Newton's method on the passive "
                     "joints failed, or they are not determined there)");
  theta_dd_.noalias() = T_ * Eigen::Map<const Eigen::VectorXd>(qdd, nd_);
  theta_dd_ += g_;
  tree_->forces(theta_.data(), theta_d_.data(), theta_dd_.data(), col_.data());  // at prepare()'s placement
  Eigen::Map<Eigen::VectorXd>(force, nd_).noalias() = T_.transpose() * col_;
}

// --- derivatives of closed loops (planar and spatial, at points and cut hinges): the forward dynamics of solve()
// written once on a scalar type and run on dual numbers. Exact first derivatives of θ_d(q) come from one Newton correction on duals
// from the closed state, θ_d = θ_d* − J_d⁻¹ c(q, θ_d*) (c vanishes there: its derivative is
// −J_d⁻¹ J_q); the rest (J, T, γ, g, τ_id, M T, Tᵀ M T) follows by the chain rule.

namespace {

// B ← A⁻¹ B (A: k × k, B: k × c, both row major), Gaussian elimination with row pivoting on the
// values; false if A is singular.
template <class S>
bool solve_small(int k, std::vector<S>& A, int c, std::vector<S>& B) {
  for (int col = 0; col < k; ++col) {
    int pivot = col;
    for (int r = col + 1; r < k; ++r)
      if (std::abs(value_of(A[r * k + col])) > std::abs(value_of(A[pivot * k + col]))) pivot = r;
    if (!(std::abs(value_of(A[pivot * k + col])) > 0.0)) return false;
    if (pivot != col) {
      for (int j = 0; j < k; ++j) std::swap(A[pivot * k + j], A[col * k + j]);
      for (int j = 0; j < c; ++j) std::swap(B[pivot * c + j], B[col * c + j]);
    }
    for (int r = col + 1; r < k; ++r) {
      const S f = A[r * k + col] / A[col * k + col];
      for (int j = col; j < k; ++j) A[r * k + j] = A[r * k + j] - f * A[col * k + j];
      for (int j = 0; j < c; ++j) B[r * c + j] = B[r * c + j] - f * B[col * c + j];
    }
  }
  for (int r = k - 1; r >= 0; --r)
    for (int j = 0; j < c; ++j) {
      S sum = B[r * c + j];
      for (int t = r + 1; t < k; ++t) sum = sum - A[r * k + t] * B[t * c + j];
      B[r * c + j] = sum / A[r * k + r];
    }
  return true;
}

}  // namespace

template <>
template <class S>
void ClosedLoopTree<PlanarAlgebra>::loop_points(const std::vector<S>& theta, const std::vector<S>* rates,
                                                  std::vector<S>& c, std::vector<S>* J, std::vector<S>* gamma) {
  const auto& bodies = tree_->bodies_;
  const int nb = static_cast<int>(bodies.size()), n = nd_ + nn_;
  // The absolute rates' coefficients w_i = ∂ω_i/∂θ̇ (constants: 1 or a hinge's sign along the
  // path, reset at an absolute rotation), once.
  if (rate_coefficients_.empty()) {
    rate_coefficients_.assign(static_cast<size_t>(nb) * n, 0.0);
    for (int i = 0; i < nb; ++i) {
      const auto& m = bodies[i];
      double* wi = rate_coefficients_.data() + static_cast<size_t>(i) * n;
      if (!m.absolute && m.parent >= 0) std::copy_n(rate_coefficients_.data() + static_cast<size_t>(m.parent) * n, n, wi);
      wi[m.dof] += m.absolute ? 1.0 : m.sign;
    }
  }
  auto w = [&](int i, int k) { return rate_coefficients_[static_cast<size_t>(i) * n + k]; };
  // The placements (PlanarAlgebra::place): absolute rotations φ, pins; the absolute rates ω.
  std::vector<S> phi(nb), px(nb), py(nb), omega(nb, S(0.0));
  for (int i = 0; i < nb; ++i) {
    const auto& m = bodies[i];
    const bool root = m.parent < 0;
    const S parent_phi = root ? S(0.0) : phi[m.parent];
    const S joint = m.absolute ? theta[m.dof] - m.offset - parent_phi : m.sign * theta[m.dof] + m.offset;
    phi[i] = parent_phi + joint;
    if (root) {
      px[i] = S(m.r.x());
      py[i] = S(m.r.y());
    } else {
      const S cp = cos(parent_phi), sp = sin(parent_phi);
      px[i] = px[m.parent] + cp * m.r.x() - sp * m.r.y();
      py[i] = py[m.parent] + sp * m.r.x() + cp * m.r.y();
    }
    if (rates)
      for (int k = 0; k < n; ++k)
        if (w(i, k) != 0.0) omega[i] = omega[i] + w(i, k) * (*rates)[k];
  }
  const int m_rows = 2 * static_cast<int>(loops_.points.size());
  c.assign(m_rows, S(0.0));
  if (J) J->assign(static_cast<size_t>(m_rows) * n, S(0.0));
  if (gamma) gamma->assign(m_rows, S(0.0));
  // A point of body i (the ground's: −1) into rows `row`, `row + 1` with sign `scale`: its
  // position, its rate rows Σ_j w_j (ẑ × s_j) and its acceleration at θ̈ = 0, −Σ_j ω_j² s_j, over
  // the bodies j on its path (s_j: from j's pin to the next pin on the path, or the point).
  auto add_point = [&](int body, const Eigen::Vector2d& b, double scale, int row) {
    S x = S(b.x()), y = S(b.y());
    if (body >= 0) {
      const S cw = cos(phi[body]), sw = sin(phi[body]);
      x = px[body] + cw * b.x() - sw * b.y();
      y = py[body] + sw * b.x() + cw * b.y();
    }
    c[row] = c[row] + scale * x;
    c[row + 1] = c[row + 1] + scale * y;
    S ex = x, ey = y;  // the end of the segment of body j on the path
    for (int j = body; j >= 0; j = bodies[j].parent) {
      const S sx = ex - px[j], sy = ey - py[j];
      if (J)
        for (int k = 0; k < n; ++k) {
          if (w(j, k) == 0.0) continue;
          (*J)[row * n + k] = (*J)[row * n + k] - scale * w(j, k) * sy;
          (*J)[(row + 1) * n + k] = (*J)[(row + 1) * n + k] + scale * w(j, k) * sx;
        }
      if (gamma) {
        const S w2 = omega[j] * omega[j];
        (*gamma)[row] = (*gamma)[row] - scale * w2 * sx;
        (*gamma)[row + 1] = (*gamma)[row + 1] - scale * w2 * sy;
      }
      ex = px[j];
      ey = py[j];
    }
  };
  int row = 0;
  for (const auto& p : loops_.points) {
    add_point(p.a, p.pa, 1.0, row);
    add_point(p.b, p.pb, -1.0, row);
    row += 2;
  }
}

template <>
template <class S>
void ClosedLoopTree<PlanarAlgebra>::tree_inverse_dynamics(const S* q, const S* qd, const S* qdd, S* force) const {
  static_cast<const PlanarTree&>(*tree_).inverse_dynamics_on(q, qd, qdd, force);
}

template <>
template <class S>
void ClosedLoopTree<SpatialAlgebra>::tree_inverse_dynamics(const S* q, const S* qd, const S* qdd, S* force) const {
  static_cast<const SpatialTree&>(*tree_).inverse_dynamics_on(q, qd, qdd, force);
}

// A cut's row r, e = U · V with U = R_o1 axis and V = R_o2 across[r] (world): ė = ω_o1 · (U × V)
// + ω_o2 · (V × U), each body's ω the sum of its path's joint rates about their world axes; at
// θ̈ = 0, ë = Ü · V + 2 U̇ · V̇ + U · V̈ with U̇ = Ω × U, Ü = A × U + Ω × U̇ (world Ω = R ω, A = R α).
template <>
template <class S>
void ClosedLoopTree<SpatialAlgebra>::add_cut_row(const std::vector<rnea::SpatialMotion<S>>& motion, const Cut& cut,
                                                 size_t r, int row, std::vector<S>& c, std::vector<S>* J,
                                                 std::vector<S>* gamma) const {
  using rnea::V3;
  const auto& bodies = tree_->bodies_;
  const int n = nd_ + nn_;
  auto world = [&](int body, const Eigen::Vector3d& b) {
    return body < 0 ? rnea::constant<S>(b) : rnea::times(motion[body].R, rnea::constant<S>(b));
  };
  const V3<S> U = world(cut.body[0], cut.axis), V = world(cut.body[1], cut.across[r]);
  c[row] = rnea::dot(U, V) - cut.value[r];
  if (J) {
    const V3<S> w = rnea::cross(U, V);
    for (int end = 0; end < 2; ++end)
      for (int j = cut.body[end]; j >= 0; j = bodies[j].parent) {
        const auto& m = bodies[j];
        if (m.prismatic) continue;
        const S rate = rnea::dot(rnea::times(motion[j].R, rnea::constant<S>(m.axis)), w);
        (*J)[row * n + m.dof] = (*J)[row * n + m.dof] + (end == 0 ? m.sign : -m.sign) * rate;
      }
  }
  if (!gamma) return;
  const V3<S> zero{S(0.0), S(0.0), S(0.0)};
  auto rates = [&](int body, const V3<S>& X, V3<S>& Xd, V3<S>& Xdd) {
    if (body < 0) {
      Xd = Xdd = zero;
      return;
    }
    const V3<S> Om = rnea::times(motion[body].R, motion[body].w), A = rnea::times(motion[body].R, motion[body].alpha);
    Xd = rnea::cross(Om, X);
    Xdd = rnea::plus(rnea::cross(A, X), rnea::cross(Om, Xd));
  };
  V3<S> Ud, Udd, Vd, Vdd;
  rates(cut.body[0], U, Ud, Udd);
  rates(cut.body[1], V, Vd, Vdd);
  (*gamma)[row] = (*gamma)[row] + rnea::dot(Udd, V) + 2.0 * rnea::dot(Ud, Vd) + rnea::dot(U, Vdd);
}

// Spatial points: the placements and motions of spatial_outward (spatial_rnea.hpp) at θ̈ = 0
// without gravity; a point's rows Σ sign (S_j) × (x − pin_j) (a sliding joint's: its axis), its
// acceleration R (a_v + α × b + ω × (v + ω × b)); then the cuts' rows (add_cut_row).
template <>
template <class S>
void ClosedLoopTree<SpatialAlgebra>::loop_points(const std::vector<S>& theta, const std::vector<S>* rates,
                                                 std::vector<S>& c, std::vector<S>* J, std::vector<S>* gamma) {
  using rnea::V3;
  const auto& bodies = tree_->bodies_;
  const int n = nd_ + nn_;
  const std::vector<S> zero(n, S(0.0));
  std::vector<rnea::SpatialMotion<S>> motion;
  rnea::spatial_outward(bodies, Eigen::Matrix<double, 6, 1>::Zero(), theta.data(), rates ? rates->data() : zero.data(),
                        zero.data(), motion);
  c.assign(m_, S(0.0));
  if (J) J->assign(static_cast<size_t>(m_) * n, S(0.0));
  if (gamma) gamma->assign(m_, S(0.0));
  auto add_point = [&](int body, const Eigen::Vector3d& b, double scale, int row) {
    const V3<S> bb = rnea::constant<S>(b);
    V3<S> x = bb;
    if (body >= 0) {
      const rnea::SpatialMotion<S>& d = motion[body];
      x = rnea::plus(d.pin, rnea::times(d.R, bb));
      if (gamma) {
        const V3<S> v = rnea::plus(d.v, rnea::cross(d.w, bb));
        const V3<S> a = rnea::times(d.R, rnea::plus(rnea::plus(d.acc, rnea::cross(d.alpha, bb)), rnea::cross(d.w, v)));
        for (int k = 0; k < 3; ++k) (*gamma)[row + k] = (*gamma)[row + k] + scale * a[k];
      }
    }
    for (int k = 0; k < 3; ++k) c[row + k] = c[row + k] + scale * x[k];
    if (!J) return;
    for (int j = body; j >= 0; j = bodies[j].parent) {
      const auto& m = bodies[j];
      const V3<S> axis = rnea::times(motion[j].R, rnea::constant<S>(m.axis));
      const V3<S> rate = m.prismatic ? axis : rnea::cross(axis, rnea::minus(x, motion[j].pin));
      for (int k = 0; k < 3; ++k) (*J)[(row + k) * n + m.dof] = (*J)[(row + k) * n + m.dof] + scale * m.sign * rate[k];
    }
  };
  int row = 0;
  for (const auto& p : loops_.points) {
    add_point(p.a, p.pa, 1.0, row);
    add_point(p.b, p.pb, -1.0, row);
    row += 3;
  }
  for (const Cut& cut : loops_.cuts)
    for (size_t r = 0; r < cut.rows.size(); ++r, ++row) add_cut_row(motion, cut, r, row, c, J, gamma);
}

template <class Algebra>
template <class S>
bool ClosedLoopTree<Algebra>::loop_dynamics(const S* q, const S* qd, const S* tau, const Eigen::MatrixXd& Jd_inverse,
                                            S* qdd) {
  const int n = nd_ + nn_;
  const char* singular = "dynamics_derivatives: the loops' Jacobian in the passive joints is singular at this state";
  // θ_d by one Newton correction on S from the closed state (J_d⁻¹ of the double solve).
  std::vector<S> theta(n), rates(n, S(0.0)), c, J, gamma;
  for (int k = 0; k < nd_; ++k) theta[k] = q[k];
  for (int k = nd_; k < n; ++k) theta[k] = S(theta_[k]);
  loop_points<S>(theta, nullptr, c, nullptr, nullptr);
  for (int i = 0; i < nn_; ++i)
    for (int r = 0; r < m_; ++r) theta[nd_ + i] = theta[nd_ + i] - Jd_inverse(i, r) * c[r];
  // T_d = −J_d⁻¹ J_q and θ̇_d = T_d q̇ at θ.
  loop_points<S>(theta, nullptr, c, &J, nullptr);
  std::vector<S> Jd(static_cast<size_t>(nn_) * nn_), Td(static_cast<size_t>(nn_) * nd_);
  for (int r = 0; r < m_; ++r) {
    for (int k = 0; k < nn_; ++k) Jd[r * nn_ + k] = J[r * n + nd_ + k];
    for (int k = 0; k < nd_; ++k) Td[r * nd_ + k] = -J[r * n + k];
  }
  std::vector<S> Jd_work = Jd;
  if (!solve_small(nn_, Jd_work, nd_, Td)) throw InputError(singular);
  for (int k = 0; k < nd_; ++k) rates[k] = qd[k];
  for (int i = 0; i < nn_; ++i)
    for (int k = 0; k < nd_; ++k) rates[nd_ + i] = rates[nd_ + i] + Td[i * nd_ + k] * qd[k];
  // g = [0; −J_d⁻¹ γ] at (θ, θ̇).
  loop_points<S>(theta, &rates, c, nullptr, &gamma);
  Jd_work = Jd;
  if (!solve_small(nn_, Jd_work, 1, gamma)) throw InputError(singular);
  std::vector<S> g(n, S(0.0)), zero(n, S(0.0)), unit(n, S(0.0)), bias(n), rest(n), column(n);
  for (int i = 0; i < nn_; ++i) g[nd_ + i] = -gamma[i];
  // Tᵀ M T q̈ = τ − Tᵀ τ_id(θ, θ̇, g), M T column by column from the inverse dynamics (affine in θ̈).
  tree_inverse_dynamics(theta.data(), rates.data(), g.data(), bias.data());
  tree_inverse_dynamics(theta.data(), zero.data(), zero.data(), rest.data());
  auto T = [&](int row, int k) -> S { return row < nd_ ? S(row == k ? 1.0 : 0.0) : Td[(row - nd_) * nd_ + k]; };
  std::vector<S> A(static_cast<size_t>(nd_) * nd_, S(0.0)), rhs(nd_);
  for (int k = 0; k < nd_; ++k) {
    for (int row = 0; row < n; ++row) unit[row] = T(row, k);
    tree_inverse_dynamics(theta.data(), zero.data(), unit.data(), column.data());
    for (int i = 0; i < nd_; ++i)
      for (int row = 0; row < n; ++row) A[i * nd_ + k] = A[i * nd_ + k] + T(row, i) * (column[row] - rest[row]);
  }
  for (int i = 0; i < nd_; ++i) {
    rhs[i] = tau[i];
    for (int row = 0; row < n; ++row) rhs[i] = rhs[i] - T(row, i) * bias[row];
  }
  // Positive definite, as solve()'s Cholesky requires (a loop that moves no mass fails here).
  Eigen::MatrixXd values(nd_, nd_);
  for (int i = 0; i < nd_; ++i)
    for (int k = 0; k < nd_; ++k) values(i, k) = value_of(A[i * nd_ + k]);
  if (Eigen::LLT<Eigen::MatrixXd>(values).info() != Eigen::Success || !solve_small(nd_, A, 1, rhs)) return false;
  for (int i = 0; i < nd_; ++i) qdd[i] = rhs[i];
  return true;
}

template <class Algebra>
bool ClosedLoopTree<Algebra>::dynamics_derivatives(int n, const double* q, const double* qd, const double* tau,
                                                   double* qdd, double* dq, double* dqd, double* dtau) {
  if (n != nd_) return false;
  if (m_ != nn_) {
    throw InputError("dynamics_derivatives: not computed on loops with redundant constraints (" + std::to_string(m_) +
                     " constraints on " + std::to_string(nn_) + " passive joints)");
  }
  if (!prepare(q, qd))
    throw InputError("dynamics_derivatives: the loops do not close at this state (Newton's method on the passive "
                     "joints failed, or they are not determined there)");
  Eigen::MatrixXd Jd_inverse(nn_, m_);  // J_d⁻¹ at the closed state: the duals' Newton correction
  qr_.solve(Eigen::MatrixXd::Identity(m_, m_), Jd_inverse);
  // The 3n directions (q, q̇, τ), kWidth at a time.
  constexpr int kWidth = 4;
  using Dual = Jet<double, kWidth>;
  std::vector<Dual> dq_in(q, q + n), dqd_in(qd, qd + n), dtau_in(tau, tau + n), out(n);
  auto variable = [&](int k) -> Dual& { return k < n ? dq_in[k] : k < 2 * n ? dqd_in[k - n] : dtau_in[k - 2 * n]; };
  for (int first = 0; first < 3 * n; first += kWidth) {
    const int last = std::min(3 * n, first + kWidth);
    for (int k = first; k < last; ++k) variable(k).d[k - first] = 1.0;
    if (!loop_dynamics(dq_in.data(), dqd_in.data(), dtau_in.data(), Jd_inverse, out.data())) return false;
    for (int k = first; k < last; ++k) {
      variable(k).d[k - first] = 0.0;
      double* target = k < n ? dq : k < 2 * n ? dqd : dtau;
      const int j = k % n;
      for (int i = 0; i < n; ++i) target[i * n + j] = out[i].d[k - first];
    }
  }
  for (int i = 0; i < n; ++i) qdd[i] = out[i].a;
  return true;
}

template <class Algebra>
void ClosedLoopTree<Algebra>::move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) {
  tree_->accelerate(theta_.data(), theta_d_.data(), theta_dd_.data(), tree_->base_acceleration_, true);
  tree_->move_coordinates(x, xd, xdd);
}

template class ClosedLoopTree<SpatialAlgebra>;
template class ClosedLoopTree<PlanarAlgebra>;

}  // namespace spacar
