// The exact derivatives of a spatial tree's forward dynamics (SpatialTree::dynamics_derivatives):
// analytic, in four O(n) passes (out, in, out again with q̈, in) and O(n²) dot products over the
// pairs of joints on one path, in the spirit of Carpentier and Mansard's derivatives of the
// recursive Newton–Euler algorithm (RSS 2018), derived here in spacar's conventions.
//
// Everything is in world axes at the world origin, vectors (angular; linear), where the joints'
// motions add up along the paths of the tree:
//   S_i = s (k; p × k)  (a hinge about the world axis k through its pin p; a sliding joint: s (0; k);
//                        s the sign of q in the joint angle),
//   v_i = v_λ + S_i q̇_i,   a_i = a_λ + S_i q̈_i + v_i × S_i q̇_i   (the ground's a: −g),
//   f_i = I_i a_i + v_i ×* I_i v_i − f_i^ext,   F_i = Σ f over i's subtree,
//   τ_i = S_iᵀ F_i + k_i q_i + d_i q̇_i   (the joint's spring and damper).
// Turning q_j moves j's subtree rigidly by the twist S_j: whatever is attached to it changes as
// ∂X = S_j × X (motions), S_j ×* X (forces), S_j ×* I − I S_j × (inertias), while the velocity
// and acceleration of j's parent λ stay. With u = S_j × v_λ and w = S_j × a_λ this gives
//   ∂v_i/∂q_j = S_j × v_i − u,   ∂a_i/∂q_j = S_j × a_i − w − u × (v_i − v_λ),
//   ∂f_i/∂q_j = S_j ×* f_i − I_i w − I_i (u × (v_i − v_λ)) − B_i u + Σ (p × (ω_j × F); ω_j × F)
// (the sum over the world-direction forces F at the points p of body i, which keep their
// direction; ω_j the angular part of S_j; B_i δv = δv ×* I_i v_i + v_i ×* I_i δv). Over a subtree
// m inside j's, with the composites Ic = Σ I_i, Q = Σ I_i (v_i ×), Bc = Σ B_i and Lc (the loads'
// matrices, Lc ω_j = Σ (p × (ω_j × F); ω_j × F)):
//   Σ_m ∂f/∂q_j = S_j ×* F_m + c_m(j),   c_m(j) = Ic (u × v_λ − w) + (Q − Bc) u + Lc ω_j.
// A joint r on the path above j (or j itself) sees F_j change: ∂τ_r/∂q_j = S_rᵀ (S_j ×* F_j + c_j(j)).
// A joint r below j turns with it, and S_rᵀ (S_j ×* F_r) cancels ∂S_rᵀ F_r = (S_j × S_r)ᵀ F_r:
// ∂τ_r/∂q_j = S_rᵀ c_r(j). In the rates, ∂v_i/∂q̇_j = S_j and ∂a_i/∂q̇_j = S_j × v_i − 2u give
// Σ_m ∂f/∂q̇_j = (Bc − Q) S_j − 2 Ic u, and M_rj = S_rᵀ Ic S_j, each with the composites of the
// deeper of r and j. Then q̈ = M⁻¹ (τ − b) and ∂q̈/∂(q, q̇) = −M⁻¹ ∂τ/∂(q, q̇) at that q̈.
//
// A floating base is a joint of six world-fixed axes S_k = e_k (unit twists) with the base's
// twist ν = (ω; v at the world origin) as its rates and the wrench at the origin as its forces;
// a pose change δ (a world twist) moves the whole tree rigidly. Its axes do not move with each
// other, and its twist holds under δ, so the formulas above hold with v_λ = ν and a_λ = the
// base's acceleration (u_k = e_k × ν, w_k = e_k × a_base), with the "above" form for both
// orders of two base axes, and with one u, not two, in ∂a/∂ν_k = e_k × v_i − u_k (no v × S ν̇
// term: the axes are fixed). The results in (δ, ν) are taken to spacar's DOFs of the base (the
// origin x and three Euler parameters μ) by the chain rule through ν = T(p) ṗ, δ = T(p) δp,
// the wrench from the generalized forces (τ = Tᵀ wrench) and p̈ from ν̇, whose derivatives are
// exact by forward-mode dual numbers (FreeBaseMaps, free_base.hpp).
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "spacar/autodiff.hpp"
#include "spacar/errors.hpp"
#include "spacar/recursive/spatial_tree.hpp"

namespace spacar {

namespace {

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

Vec6 cross_motion(const Vec6& x, const Vec6& y) {  // x × y
  Vec6 out;
  out << x.head<3>().cross(y.head<3>()), x.head<3>().cross(y.tail<3>()) + x.tail<3>().cross(y.head<3>());
  return out;
}

// M⁻¹ (row major) of a symmetric positive definite M by Cholesky, written out: at a robot's n
// (6 to 12) Eigen's dynamic-size factorization, triangular solves and products cost more than
// their arithmetic. M is overwritten by its factor L, Linv by L⁻¹; false if M is not positive
// definite.
bool cholesky_inverse(Eigen::MatrixXd& M, Eigen::MatrixXd& Linv, double* inverse) {
  const int n = static_cast<int>(M.rows());
  for (int j = 0; j < n; ++j) {  // M = L Lᵀ, L in M's lower triangle
    double d = M(j, j);
    for (int k = 0; k < j; ++k) d -= M(j, k) * M(j, k);
    if (!(d > 0.0)) return false;
    d = std::sqrt(d);
    M(j, j) = d;
    for (int i = j + 1; i < n; ++i) {
      double s = M(i, j);
      for (int k = 0; k < j; ++k) s -= M(i, k) * M(j, k);
      M(i, j) = s / d;
    }
  }
  Linv.setZero(n, n);
  for (int j = 0; j < n; ++j) {
    Linv(j, j) = 1.0 / M(j, j);
    for (int i = j + 1; i < n; ++i) {
      double s = 0.0;
      for (int k = j; k < i; ++k) s -= M(i, k) * Linv(k, j);
      Linv(i, j) = s / M(i, i);
    }
  }
  for (int i = 0; i < n; ++i)  // M⁻¹ = L⁻ᵀ L⁻¹
    for (int j = 0; j <= i; ++j) {
      double s = 0.0;
      for (int k = i; k < n; ++k) s += Linv(k, i) * Linv(k, j);
      inverse[i * n + j] = inverse[j * n + i] = s;
    }
  return true;
}

// f's value (out, m) and its m × 6 Jacobians in each of its arguments (J[a], row major), at
// double arguments args[a] (6 each), by one pass on dual numbers over all of them.
template <int A, class F>
void jacobians(const F& f, const std::array<const double*, A>& args, int m, double* out, double* const* J) {
  using J6 = Jet<double, 6 * A>;
  std::array<std::array<J6, 6>, A> in;
  for (int a = 0; a < A; ++a)
    for (int c = 0; c < 6; ++c) in[a][c] = J6::variable(args[a][c], 6 * a + c);
  std::array<J6, 6> res;
  f(in, res.data());
  for (int r = 0; r < m; ++r) {
    out[r] = res[r].a;
    for (int a = 0; a < A; ++a)
      for (int c = 0; c < 6; ++c) J[a][r * 6 + c] = res[r].d[6 * a + c];
  }
}

// A floating base's state in the passes' terms at p = (x, μ), ṗ and its generalized forces τ_p:
// its twist ν = T(p) ṗ and the wrench w = T⁻ᵀ(p) τ_p, with their Jacobians (row major, 6 × 6):
// T = ∂ν/∂ṗ (also δ = T δp), Np = ∂ν/∂p, Wp = ∂w/∂p, Wt = ∂w/∂τ_p = T⁻ᵀ.
struct BaseState {
  Eigen::Matrix<double, 6, 1> nu, wrench;
  double T[36], Np[36], Wp[36], Wt[36];

  BaseState(const FreeBaseMaps& maps, const double* p, const double* pd, const double* tau) {
    double* J[2] = {Np, T};
    jacobians<2>([&](const auto& in, auto* out) { maps.twist(in[0].data(), in[1].data(), out); },
                 {p, pd}, 6, nu.data(), J);
    double* K[2] = {Wp, Wt};
    jacobians<2>([&](const auto& in, auto* out) { maps.wrench(in[0].data(), in[1].data(), out); },
                 {p, tau}, 6, wrench.data(), K);
  }
};

// The floating base's results in (ν, joints) taken to q by the chain rule: a column of the base's
// coordinates p_m gathers the columns of δ (through δ = T δp), of ν (ν = T(p) ṗ depends on p) and
// of the wrench (w = T⁻ᵀ(p) τ_p); q̇'s through T, τ's through T⁻ᵀ. A row of p̈ is P(p, ṗ, ν̇),
// with its explicit derivatives in p and ṗ beside ∂P/∂ν̇ times the rows of ν̇.
// qdd_t, Aq, Aqd, At: q̈ and the derivatives in (ν, joints) (Aq, Aqd, At overwritten).
void base_to_coordinates(int n, const FreeBaseMaps& maps, const BaseState& base, const std::array<int, 6>& bidx,
                         const std::array<int, 6>& tidx, const double* p, const double* pd, const double* qdd_t,
                         double* Aq, double* Aqd, double* At, double* qdd, double* dq, double* dqd, double* dtau) {
  const double *T = base.T, *Np = base.Np, *Wp = base.Wp, *Wt = base.Wt;
  double nud[6], pdd[6], Pp[36], Ppd[36], Pn[36];
  for (int k = 0; k < 6; ++k) nud[k] = qdd_t[tidx[k]];
  {
    double* J[3] = {Pp, Ppd, Pn};
    jacobians<3>([&](const auto& in, auto* out) { maps.acceleration(in[0].data(), in[1].data(), in[2].data(), out); },
                 {p, pd, nud}, 6, pdd, J);
  }
  // Columns, in place (At: ∂/∂w, Aq: ∂/∂δ, Aqd: ∂/∂ν).
  for (int i = 0; i < n; ++i) {
    double aq[6], aqd[6], at[6];
    for (int k = 0; k < 6; ++k) {
      aq[k] = Aq[i * n + tidx[k]];
      aqd[k] = Aqd[i * n + tidx[k]];
      at[k] = At[i * n + tidx[k]];
    }
    for (int m = 0; m < 6; ++m) {
      double cq = 0.0, cqd = 0.0, ct = 0.0;
      for (int k = 0; k < 6; ++k) {
        cq += aq[k] * T[k * 6 + m] + aqd[k] * Np[k * 6 + m] + at[k] * Wp[k * 6 + m];
        cqd += aqd[k] * T[k * 6 + m];
        ct += at[k] * Wt[k * 6 + m];
      }
      Aq[i * n + bidx[m]] = cq;
      Aqd[i * n + bidx[m]] = cqd;
      At[i * n + bidx[m]] = ct;
    }
  }
  // Rows: the joints' as they are, the base's through P.
  using Values = Eigen::Map<Eigen::VectorXd>;
  using ConstValues = Eigen::Map<const Eigen::VectorXd>;
  Values(qdd, n) = ConstValues(qdd_t, n);
  Values(dq, n * n) = ConstValues(Aq, n * n);
  Values(dqd, n * n) = ConstValues(Aqd, n * n);
  Values(dtau, n * n) = ConstValues(At, n * n);
  for (int r = 0; r < 6; ++r) {
    const int row = bidx[r];
    qdd[row] = pdd[r];
    for (int c = 0; c < n; ++c) {
      double sq = 0.0, sqd = 0.0, st = 0.0;
      for (int k = 0; k < 6; ++k) {
        const double w = Pn[r * 6 + k];
        sq += w * Aq[tidx[k] * n + c];
        sqd += w * Aqd[tidx[k] * n + c];
        st += w * At[tidx[k] * n + c];
      }
      dq[row * n + c] = sq;
      dqd[row * n + c] = sqd;
      dtau[row * n + c] = st;
    }
    for (int m = 0; m < 6; ++m) {
      dq[row * n + bidx[m]] += Pp[r * 6 + m];
      dqd[row * n + bidx[m]] += Ppd[r * 6 + m];
    }
  }
}

}  // namespace

bool SpatialTree::dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd,
                                       double* dq, double* dqd, double* dtau) {
  const int nb = n_bodies();
  if (n != (floating_ ? nb + 5 : nb)) return false;  // a DOF per joint, a floating root's six
  DerivativeWork& work = derivative_work_;
  std::vector<WorldBody>& world = work.bodies;
  world.resize(nb);
  // A floating base: where its DOFs are in q, as p = (x, μ) (bidx) and as the slots of its twist
  // ν = (ω; v at the origin) and wrench (tidx) in the passes; ν, and the wrench of tau's forces
  // on p. The passes then run in (ν, joints), their results taken to q at the end.
  std::array<int, 6> bidx{}, tidx{};
  double base_p[6] = {}, base_pd[6] = {}, base_tau[6] = {};
  std::optional<BaseState> base;
  Vec6 nu = Vec6::Zero();
  Eigen::Vector4d base_l = Eigen::Vector4d::Zero();
  const double* tau_t = tau;
  if (floating_) {
    for (int c = 0; c < 3; ++c) {
      bidx[c] = tidx[3 + c] = base_.x_dof + c;
      bidx[3 + c] = tidx[c] = base_.lambda_dof[c];
    }
    for (int m = 0; m < 6; ++m) {
      base_p[m] = q[bidx[m]];
      base_pd[m] = qd[bidx[m]];
      base_tau[m] = tau[bidx[m]];
    }
    base_l = base_lambda(q);
    if (!(std::abs(base_l[base_.dependent]) > 0.0) || !base_l.allFinite())
      throw InputError("dynamics_derivatives: the floating base's three Euler parameters have a norm of 1 or more");
    base.emplace(base_, base_p, base_pd, base_tau);
    nu = base->nu;
    work.tau_t = Eigen::Map<const Eigen::VectorXd>(tau, n);
    for (int k = 0; k < 6; ++k) work.tau_t[tidx[k]] = base->wrench[k];
    tau_t = work.tau_t.data();
  }
  // Outwards: placements, joint axes, inertias, velocities, the accelerations without q̈, the
  // external loads and their matrices.
  int base_body = -1;  // the floating base's body
  for (int i = 0; i < nb; ++i) {
    const Model& m = bodies_[i];
    WorldBody& b = world[i];
    const bool root = m.parent < 0;
    if (m.free) {  // the floating base: its frame R(λ) R0ᵀ at its origin, no joint
      base_body = i;
      b.R = euler_R(base_l) * base_.R0.transpose();
      b.p = Vec3(base_p[0], base_p[1], base_p[2]);
      b.S.setZero();
    } else {
      // The placement of SpatialAlgebra::place without its Euler parameters: turned about (or
      // slid along) the axis k, the same in the parent's and the body's coordinates.
      const double theta = m.sign * q[m.dof] + m.offset;
      const Vec3& k = m.axis;
      Mat3 rel = Mat3::Identity();  // body → parent
      Vec3 r = m.r;
      if (m.prismatic) r += theta * k;
      else rel = SpatialAlgebra::axis_rotation(k, std::cos(theta), std::sin(theta));
      if (root) {
        b.R = rel;
        b.p = r;
      } else {
        const WorldBody& parent = world[m.parent];
        b.R.noalias() = parent.R * rel;
        b.p.noalias() = parent.p + parent.R * r;
      }
      const Vec3 axis = b.R * k;
      if (m.prismatic) b.S << Vec3::Zero(), m.sign * axis;
      else b.S << m.sign * axis, m.sign * b.p.cross(axis);
    }
    SpatialAlgebra::Frame to_world;  // world → body coordinates at the pin, as a child's frame
    to_world.E = b.R.transpose();
    to_world.r = b.p;
    b.I.setZero();
    SpatialAlgebra::add_inertia_to_parent(m, to_world, m.inertia, b.I);
    b.parent_v = root ? Vec6::Zero() : world[m.parent].v;
    b.parent_a = root ? base_acceleration_ : world[m.parent].a;
    if (m.free) {
      b.v = nu;
      b.a = b.parent_a;
    } else {
      b.v = b.parent_v + b.S * qd[m.dof];
      b.a = b.parent_a + cross_motion(b.v, b.S) * qd[m.dof];
    }
    b.f = -SpatialAlgebra::to_parent(m, to_world, m.load);  // −f^ext, the body-fixed load
    b.L.setZero();
  }
  for (const Load& l : loads_) {
    WorldBody& b = world[l.body];
    const Vec3 p = b.p + b.R * l.b, F = l.force;
    b.f.head<3>() -= p.cross(F);
    b.f.tail<3>() -= F;
    b.L.topRows<3>() += p.dot(F) * Mat3::Identity() - F * p.transpose();
    b.L.bottomRows<3>() -= skew(F);
  }
  // Inwards: the composite inertias and the bias forces b(q, q̇) = τ at q̈ = 0.
  Eigen::VectorXd& bias = work.bias;
  bias.resize(n);
  for (int i = 0; i < nb; ++i) {
    WorldBody& b = world[i];
    b.Ic = b.I;
    b.F = b.f + b.I * b.a + SpatialAlgebra::cross_force(b.v, b.I * b.v);
  }
  for (int i = nb - 1; i >= 0; --i) {
    const Model& m = bodies_[i];
    WorldBody& b = world[i];
    if (m.free)
      for (int k = 0; k < 6; ++k) bias[tidx[k]] = b.F[k];
    else
      bias[m.dof] = b.S.dot(b.F) + m.stiffness * q[m.dof] + m.damping * qd[m.dof];
    b.IS = b.Ic * b.S;
    if (m.parent >= 0) {
      world[m.parent].Ic += b.Ic;
      world[m.parent].F += b.F;
    }
  }
  // M_rj = S_rᵀ Ic_j S_j for r on the path from j to the root (the base's axes: Ic_j S_j).
  Eigen::MatrixXd& M = work.M;
  M.setZero(n, n);
  for (int j = 0; j < nb; ++j) {
    if (bodies_[j].free) {
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 6; ++c) M(tidx[a], tidx[c]) = world[j].Ic(a, c);
      continue;
    }
    const int dj = bodies_[j].dof;
    for (int r = j; r >= 0; r = bodies_[r].parent) {
      if (bodies_[r].free) {
        for (int k = 0; k < 6; ++k) M(tidx[k], dj) = M(dj, tidx[k]) = world[j].IS[k];
        break;
      }
      const double value = world[r].S.dot(world[j].IS);
      M(bodies_[r].dof, dj) = value;
      M(dj, bodies_[r].dof) = value;
    }
  }
  // In (ν, joints) for a floating base (taken to q below), else straight into the results.
  if (floating_) {
    work.inverse.resize(n * n);
    work.qdd_t.resize(n);
    work.dq_t.resize(n * n);
    work.dqd_t.resize(n * n);
  }
  double* inverse = floating_ ? work.inverse.data() : dtau;  // ∂q̈/∂τ = M⁻¹
  double* acc = floating_ ? work.qdd_t.data() : qdd;
  double* acc_q = floating_ ? work.dq_t.data() : dq;
  double* acc_qd = floating_ ? work.dqd_t.data() : dqd;
  if (!cholesky_inverse(M, work.Linv, inverse)) return false;
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int j = 0; j < n; ++j) s += inverse[i * n + j] * (tau_t[j] - bias[j]);
    acc[i] = s;
  }
  // Outwards again with q̈: the accelerations and the body forces; then inwards the composites
  // of the derivatives.
  for (int i = 0; i < nb; ++i) {
    const Model& m = bodies_[i];
    WorldBody& b = world[i];
    if (m.parent >= 0) {
      const Vec6 change = world[m.parent].a - b.parent_a;  // the parent's q̈ terms
      b.parent_a += change;
      b.a += change;
    }
    if (m.free)
      for (int k = 0; k < 6; ++k) b.a[k] += acc[tidx[k]];
    else
      b.a += b.S * acc[m.dof];
    const Vec6 h = b.I * b.v;
    b.f += b.I * b.a + SpatialAlgebra::cross_force(b.v, h);
    // I (v ×) − B = −Pᵀ − P − G with P = (v ×*) I (I (v ×) = −Pᵀ, I being symmetric) and
    // G δv = δv ×* h = −(h_ω × δω + h_v × δu; h_v × δω).
    Mat6 P;
    for (int c = 0; c < 6; ++c) P.col(c) = SpatialAlgebra::cross_force(b.v, b.I.col(c));
    b.QmB = -P - P.transpose();
    const Mat3 hw = skew(h.head<3>()), hl = skew(h.tail<3>());
    b.QmB.topLeftCorner<3, 3>() += hw;
    b.QmB.topRightCorner<3, 3>() += hl;
    b.QmB.bottomLeftCorner<3, 3>() += hl;
  }
  for (int i = nb - 1; i >= 0; --i) {
    const Model& m = bodies_[i];
    WorldBody& b = world[i];
    b.u = cross_motion(b.S, b.parent_v);
    b.z = cross_motion(b.u, b.parent_v) - cross_motion(b.S, b.parent_a);
    b.QmBS = b.QmB.transpose() * b.S;
    b.LS = b.L.transpose() * b.S;
    if (m.parent >= 0) {
      WorldBody& parent = world[m.parent];
      parent.f += b.f;
      parent.QmB += b.QmB;
      parent.L += b.L;
    }
  }
  // The base's axes e_k: u_k = e_k × ν and z_k = u_k × ν − e_k × a_base.
  std::array<Vec6, 6> base_u, base_z;
  if (base_body >= 0)
    for (int k = 0; k < 6; ++k) {
      const Vec6 e = Vec6::Unit(k);
      base_u[k] = cross_motion(e, nu);
      base_z[k] = cross_motion(base_u[k], nu) - cross_motion(e, world[base_body].a);
    }
  // The pairs (r, j), r on the path from j to the root: ∂τ_r/∂(q_j, q̇_j) from j's composites,
  // and for r above j, ∂τ_j/∂(q_r, q̇_r) from j's composites.
  Eigen::MatrixXd &dtau_dq = work.dtau_dq, &dtau_dqd = work.dtau_dqd;
  dtau_dq.setZero(n, n);
  dtau_dqd.setZero(n, n);
  for (int j = 0; j < nb; ++j) {
    const Model& mj = bodies_[j];
    const WorldBody& b = world[j];
    if (mj.free) {  // the base's axes among themselves: each in the "above" form
      for (int c = 0; c < 6; ++c) {
        const Vec6 e = Vec6::Unit(c);
        Vec6 y_q = SpatialAlgebra::cross_force(e, b.f) + b.Ic * base_z[c] + b.QmB * base_u[c];
        if (c < 3) y_q += b.L.col(c);
        const Vec6 y_qd = -(b.QmB * e) - b.Ic * base_u[c];
        for (int a = 0; a < 6; ++a) {
          dtau_dq(tidx[a], tidx[c]) = y_q[a];
          dtau_dqd(tidx[a], tidx[c]) = y_qd[a];
        }
      }
      continue;
    }
    const Vec6 y_q = SpatialAlgebra::cross_force(b.S, b.f) + b.Ic * b.z + b.QmB * b.u + b.L * b.S.head<3>();
    const Vec6 y_qd = -(b.QmB * b.S) - 2.0 * (b.Ic * b.u);
    for (int r = j; r >= 0; r = bodies_[r].parent) {
      if (bodies_[r].free) {  // the base above j: its axes stay, j's subtree moves with them
        for (int k = 0; k < 6; ++k) {
          dtau_dq(tidx[k], mj.dof) = y_q[k];
          dtau_dqd(tidx[k], mj.dof) = y_qd[k];
          dtau_dq(mj.dof, tidx[k]) = b.IS.dot(base_z[k]) + b.QmBS.dot(base_u[k]) + (k < 3 ? b.LS[k] : 0.0);
          dtau_dqd(mj.dof, tidx[k]) = -b.QmBS[k] - b.IS.dot(base_u[k]);
        }
        break;
      }
      const WorldBody& br = world[r];
      const int dr = bodies_[r].dof;
      dtau_dq(dr, mj.dof) = br.S.dot(y_q);
      dtau_dqd(dr, mj.dof) = br.S.dot(y_qd);
      if (r == j) continue;
      dtau_dq(mj.dof, dr) = b.IS.dot(br.z) + b.QmBS.dot(br.u) + b.LS.dot(br.S.head<3>());
      dtau_dqd(mj.dof, dr) = -b.QmBS.dot(br.S) - 2.0 * b.IS.dot(br.u);
    }
    dtau_dq(mj.dof, mj.dof) += mj.stiffness;
    dtau_dqd(mj.dof, mj.dof) += mj.damping;
  }
  // ∂q̈/∂(q, q̇) = −M⁻¹ ∂τ/∂(q, q̇), row major.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double sq = 0.0, sqd = 0.0;
      for (int k = 0; k < n; ++k) {
        sq += inverse[i * n + k] * dtau_dq(k, j);
        sqd += inverse[i * n + k] * dtau_dqd(k, j);
      }
      acc_q[i * n + j] = -sq;
      acc_qd[i * n + j] = -sqd;
    }
  if (floating_)
    base_to_coordinates(n, base_, *base, bidx, tidx, base_p, base_pd, acc, acc_q, acc_qd, inverse, qdd, dq, dqd, dtau);
  return true;
}

}  // namespace spacar
