// Closed loops on the recursive path (closed_loop.hpp): the loops' constraints on a spatial tree,
// closed by Newton's method in the dependent joints, and the equations of motion in the DOFs.
#include "spacar/recursive/closed_loop.hpp"

#include <algorithm>
#include <cmath>

#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"

namespace spacar {

namespace {

constexpr int kMaxIterations = 30;
// Newton's method stops at residuals of 1e-14 (points: of the tree's size), near round-off: at
// 1e-12 the accelerations were off by 1e-11 (relative), or at a correction at round-off.
constexpr double kResidual = 1e-14, kRoundOff = 1e-15;

// The Euler parameters of a LAMBDA node on a body (body < 0: the ground) from its parameters at
// the recognition.
Eigen::Vector4d node_lambda(const SpatialTree::Loops::Cut& cut, int end, const Eigen::Vector4d& body_lambda) {
  return cut.body[end] < 0 ? cut.lambda0[end] : tree_detail::compose(body_lambda, cut.lambda0[end]);
}

}  // namespace

ClosedLoopTree::ClosedLoopTree(std::unique_ptr<SpatialTree> tree) : tree_(std::move(tree)), loops_(tree_->loops()) {
  nd_ = loops_.n_dof;
  nn_ = static_cast<int>(loops_.dependent0.size());
  m_ = 3 * static_cast<int>(loops_.points.size());
  for (const SpatialTree::Loops::Cut& cut : loops_.cuts) m_ += static_cast<int>(cut.rows.size());
  const int n = nd_ + nn_;
  theta_ = theta_d_ = theta_dd_ = zero_ = g_ = col_ = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < nn_; ++k) theta_[nd_ + k] = loops_.dependent0[k];
  c_ = gamma_ = Eigen::VectorXd::Zero(m_);
  q_last_ = rhs_ = Eigen::VectorXd::Zero(nd_);
  start_ = step_ = Eigen::VectorXd::Zero(nn_);
  J_ = Eigen::MatrixXd::Zero(m_, n);
  T_ = MT_ = Eigen::MatrixXd::Zero(n, nd_);
  A_ = Eigen::MatrixXd::Zero(nd_, nd_);
  qr_ = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(m_, nn_);
  llt_ = Eigen::LLT<Eigen::MatrixXd>(nd_);
  T_.topRows(nd_).setIdentity();
  length_ = 0.0;
  for (const auto& body : tree_->bodies_) length_ += body.r.norm();
  for (const SpatialTree::Loops::Point& p : loops_.points) length_ = std::max(length_, p.pa.norm());
  if (!(length_ > 0.0)) length_ = 1.0;
}

std::unique_ptr<RecursiveTree> ClosedLoopTree::close(std::unique_ptr<SpatialTree> tree, const System& sys,
                                                     const Data& data, std::string* why) {
  auto loop = std::unique_ptr<ClosedLoopTree>(new ClosedLoopTree(std::move(tree)));
  // The assembled state: q holds the DOF joints' e1 (a loop's tree has no DYNX).
  for (int k = 0; k < loop->nd_; ++k) loop->q_last_[k] = loop->theta_[k] = data.e[sys.e_dyn[k]];
  loop->tree_->outward(loop->theta_.data(), loop->zero_.data());
  loop->constraints();
  loop->qr_.compute(loop->J_.rightCols(loop->nn_));
  if (loop->qr_.rank() < loop->nn_) {
    if (why) {
      *why = "the loops do not determine their " + std::to_string(loop->nn_) + " passive joints (" +
             std::to_string(loop->m_) + " constraints of rank " + std::to_string(loop->qr_.rank()) + ")";
    }
    return nullptr;
  }
  return loop;
}

void ClosedLoopTree::add_point_rows(int body, const Vec3& p, double scale, int row) {
  for (int j = body; j >= 0; j = tree_->bodies_[j].parent) {
    const auto& m = tree_->bodies_[j];
    const auto& d = tree_->work_[j];
    const Vec3 axis = d.frame.R * m.axis;
    const Vec3 rate = m.prismatic ? axis : Vec3(axis.cross(p - d.pin));
    J_.block<3, 1>(row, m.dof) += scale * m.sign * rate;
  }
}

void ClosedLoopTree::add_rotation_row(int body, const Eigen::Matrix<double, 1, 3>& w, int row) {
  for (int j = body; j >= 0; j = tree_->bodies_[j].parent) {
    const auto& m = tree_->bodies_[j];
    if (!m.prismatic) J_(row, m.dof) += m.sign * w.dot(tree_->work_[j].frame.R * m.axis);
  }
}

// Points: c = x_a − x_b, ẋ = Σ (S_j θ̇_j) × (x − pin_j) over the joints on a body's path (a sliding
// joint's: its axis). Cuts: c = e_k(λ_o1, λ_o2) − e_k(recognition), ∂e/∂θ_j = B ½ E(λ)ᵀ ω_j
// (λ̇ = ½ E(λ)ᵀ ω, world ω).
void ClosedLoopTree::constraints() {
  J_.setZero();
  const auto& work = tree_->work_;
  int row = 0;
  for (const SpatialTree::Loops::Point& p : loops_.points) {
    const Vec3 xa = work[p.a].pin + work[p.a].frame.R * p.pa;
    const Vec3 xb = p.b < 0 ? p.pb : Vec3(work[p.b].pin + work[p.b].frame.R * p.pb);
    c_.segment<3>(row) = xa - xb;
    add_point_rows(p.a, xa, 1.0, row);
    if (p.b >= 0) add_point_rows(p.b, xb, -1.0, row);
    row += 3;
  }
  for (const SpatialTree::Loops::Cut& cut : loops_.cuts) {
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

// After the tree's accelerations at θ̈ = 0 without gravity (d.a, body coordinates): a point's
// acceleration R (a_v + α × b + ω × (v + ω × b)); a cut's ë = B ẍ + c(x, ẋ) with
// λ̈ = ½ E(λ̇)ᵀ ω + ½ E(λ)ᵀ α (world ω, α).
void ClosedLoopTree::constraint_bias() {
  const auto& work = tree_->work_;
  auto point_acceleration = [&](int body, const Vec3& b) -> Vec3 {
    const auto& d = work[body];
    const Vec3 w = d.v.head<3>(), v = d.v.tail<3>() + w.cross(b);
    return d.frame.R * (d.a.tail<3>() + d.a.head<3>().cross(b) + w.cross(v));
  };
  int row = 0;
  for (const SpatialTree::Loops::Point& p : loops_.points) {
    gamma_.segment<3>(row) = point_acceleration(p.a, p.pa);
    if (p.b >= 0) gamma_.segment<3>(row) -= point_acceleration(p.b, p.pb);
    row += 3;
  }
  for (const SpatialTree::Loops::Cut& cut : loops_.cuts) {
    Eigen::Matrix<double, 8, 1> x, xd = Eigen::Matrix<double, 8, 1>::Zero(), xdd = xd;
    Eigen::Vector3d e, conv;
    Eigen::Matrix<double, 3, 8> B;
    for (int end = 0; end < 2; ++end) {
      const int body = cut.body[end];
      const Eigen::Vector4d l = node_lambda(cut, end, body < 0 ? cut.lambda0[end] : work[body].frame.lambda);
      x.segment<4>(4 * end) = l;
      if (body < 0) continue;
      const auto& d = work[body];
      const Vec3 w = d.frame.R * d.v.head<3>(), alpha = d.frame.R * d.a.head<3>();
      const Eigen::Vector4d ld = 0.5 * euler_E(l).transpose() * w;
      xd.segment<4>(4 * end) = ld;
      xdd.segment<4>(4 * end) = 0.5 * (euler_E(ld).transpose() * w + euler_E(l).transpose() * alpha);
    }
    cut.kernel->first_derivatives(x.data(), e.data(), B.data());
    cut.kernel->convective(x.data(), xd.data(), conv.data());
    for (size_t r = 0; r < cut.rows.size(); ++r, ++row) {
      const int k = cut.rows[r];
      gamma_[row] = B.row(k).dot(xdd) + conv[k];
    }
  }
}

bool ClosedLoopTree::close_loops(const double* q) {
  start_ = theta_.tail(nn_);
  // First from the last closed state moved along its tangent, θ_d + T_d (q − q_last), which
  // leaves a residual of second order in the step (an integrator's stages are close to each
  // other); if that fails, from the last closed state itself.
  for (int k = 0; k < nd_; ++k) q_last_[k] = q[k] - q_last_[k];
  theta_.tail(nn_).noalias() += T_.bottomRows(nn_) * q_last_;
  for (int k = 0; k < nd_; ++k) q_last_[k] = q[k] - q_last_[k];  // back to the last closed state's
  for (int k = 0; k < nd_; ++k) theta_[k] = q[k];
  if (newton()) return closed(q);
  theta_.tail(nn_) = start_;
  if (newton()) return closed(q);
  theta_.tail(nn_) = start_;
  return false;
}

bool ClosedLoopTree::newton() {
  const int n_point_rows = 3 * static_cast<int>(loops_.points.size());
  for (int it = 0; it < kMaxIterations; ++it) {
    tree_->outward(theta_.data(), zero_.data());
    constraints();
    qr_.compute(J_.rightCols(nn_));
    if (qr_.rank() < nn_) return false;
    double residual = 0.0;
    for (int r = 0; r < m_; ++r) residual = std::max(residual, std::abs(c_[r]) / (r < n_point_rows ? length_ : 1.0));
    if (residual <= kResidual) return true;
    if (!std::isfinite(residual)) return false;
    step_ = qr_.solve(c_);
    theta_.tail(nn_) -= step_;
    if (step_.cwiseAbs().maxCoeff() <= kRoundOff * (1.0 + theta_.tail(nn_).cwiseAbs().maxCoeff())) return true;
  }
  return false;
}

bool ClosedLoopTree::closed(const double* q) {
  for (int k = 0; k < nd_; ++k) q_last_[k] = q[k];
  return true;
}

bool ClosedLoopTree::prepare(const double* q, const double* qd) {
  if (!close_loops(q)) return false;
  T_.bottomRows(nn_) = -qr_.solve(J_.leftCols(nd_));
  const Eigen::Map<const Eigen::VectorXd> rates(qd, nd_);
  theta_d_.head(nd_) = rates;
  theta_d_.tail(nn_).noalias() = T_.bottomRows(nn_) * rates;
  tree_->outward(theta_.data(), theta_d_.data());
  tree_->applied_loads();
  tree_->accelerate(theta_.data(), theta_d_.data(), zero_.data(), SpatialTree::Vector::Zero(), true);
  constraint_bias();
  g_.tail(nn_) = -qr_.solve(gamma_);
  return true;
}

bool ClosedLoopTree::solve(const double* q, const double* qd, double* qdd) {
  if (!prepare(q, qd)) return false;
  SpatialTree& tree = *tree_;
  // τ_id(θ, θ̇, g): the forces of the accelerations g, the bias forces and the loads.
  tree.accelerate(theta_.data(), theta_d_.data(), g_.data(), tree.base_acceleration_, true);
  for (size_t i = 0; i < tree.bodies_.size(); ++i) tree.work_[i].pA += tree.bodies_[i].inertia * tree.work_[i].a;
  tree.joint_forces(theta_.data(), col_.data(), true);
  rhs_.noalias() = -T_.transpose() * col_;
  for (int k = 0; k < nd_; ++k) tree.mass_times(T_.col(k).data(), MT_.col(k).data());
  A_.noalias() = T_.transpose() * MT_;
  llt_.compute(A_);
  if (llt_.info() != Eigen::Success) return false;
  Eigen::Map<Eigen::VectorXd> out(qdd, nd_);
  out = llt_.solve(rhs_);
  theta_dd_.noalias() = T_ * out;
  theta_dd_ += g_;
  tree.accelerate(theta_.data(), theta_d_.data(), theta_dd_.data(), tree.base_acceleration_, true);
  return out.allFinite();
}

void ClosedLoopTree::inverse_dynamics(const double* q, const double* qd, const double* qdd, double* force) {
  if (!prepare(q, qd))
    throw InputError("inverse_dynamics: the loops do not close at this state (Newton's method on the passive "
                     "joints failed, or they are not determined there)");
  theta_dd_.noalias() = T_ * Eigen::Map<const Eigen::VectorXd>(qdd, nd_);
  theta_dd_ += g_;
  tree_->inverse_dynamics(theta_.data(), theta_d_.data(), theta_dd_.data(), col_.data());
  Eigen::Map<Eigen::VectorXd>(force, nd_).noalias() = T_.transpose() * col_;
}

bool ClosedLoopTree::dynamics_derivatives(int, const double*, const double*, const double*, double*, double*, double*,
                                          double*) {
  throw InputError("dynamics_derivatives: not computed on closed loops (the recursive path computes them on trees; "
                   "inverse_dynamics and simulate take closed loops)");
}

void ClosedLoopTree::move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const {
  tree_->move_coordinates(x, xd, xdd);
}

}  // namespace spacar
