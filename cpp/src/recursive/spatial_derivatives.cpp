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
#include <cmath>
#include <vector>

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

}  // namespace

bool SpatialTree::dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd,
                                       double* dq, double* dqd, double* dtau) {
  const int nb = n_bodies();
  if (n != nb) return false;  // every body turned by one joint, its DOF (not a floating base's six)
  DerivativeWork& work = derivative_work_;
  std::vector<WorldBody>& world = work.bodies;
  world.resize(nb);
  // Outwards: placements, joint axes, inertias, velocities, the accelerations without q̈, the
  // external loads and their matrices.
  for (int i = 0; i < nb; ++i) {
    const Model& m = bodies_[i];
    WorldBody& b = world[i];
    const bool root = m.parent < 0;
    // The placement of SpatialAlgebra::place without its Euler parameters: turned about (or slid
    // along) the axis k, the same in the parent's and the body's coordinates.
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
    SpatialAlgebra::Frame to_world;  // world → body coordinates at the pin, as a child's frame
    to_world.E = b.R.transpose();
    to_world.r = b.p;
    b.I.setZero();
    SpatialAlgebra::add_inertia_to_parent(m, to_world, m.inertia, b.I);
    b.parent_v = root ? Vec6::Zero() : world[m.parent].v;
    b.parent_a = root ? base_acceleration_ : world[m.parent].a;
    b.v = b.parent_v + b.S * qd[m.dof];
    b.a = b.parent_a + cross_motion(b.v, b.S) * qd[m.dof];
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
    bias[m.dof] = b.S.dot(b.F) + m.stiffness * q[m.dof] + m.damping * qd[m.dof];
    b.IS = b.Ic * b.S;
    if (m.parent >= 0) {
      world[m.parent].Ic += b.Ic;
      world[m.parent].F += b.F;
    }
  }
  // M_rj = S_rᵀ Ic_j S_j for r on the path from j to the root.
  Eigen::MatrixXd& M = work.M;
  M.setZero(n, n);
  for (int j = 0; j < nb; ++j)
    for (int r = j; r >= 0; r = bodies_[r].parent) {
      const double value = world[r].S.dot(world[j].IS);
      M(bodies_[r].dof, bodies_[j].dof) = value;
      M(bodies_[j].dof, bodies_[r].dof) = value;
    }
  double* inverse = dtau;  // ∂q̈/∂τ = M⁻¹
  if (!cholesky_inverse(M, work.Linv, inverse)) return false;
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int j = 0; j < n; ++j) s += inverse[i * n + j] * (tau[j] - bias[j]);
    qdd[i] = s;
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
    b.a += b.S * qdd[m.dof];
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
  // The pairs (r, j), r on the path from j to the root: ∂τ_r/∂(q_j, q̇_j) from j's composites,
  // and for r above j, ∂τ_j/∂(q_r, q̇_r) from j's composites.
  Eigen::MatrixXd &dtau_dq = work.dtau_dq, &dtau_dqd = work.dtau_dqd;
  dtau_dq.setZero(n, n);
  dtau_dqd.setZero(n, n);
  for (int j = 0; j < nb; ++j) {
    const Model& mj = bodies_[j];
    const WorldBody& b = world[j];
    const Vec6 y_q = SpatialAlgebra::cross_force(b.S, b.f) + b.Ic * b.z + b.QmB * b.u + b.L * b.S.head<3>();
    const Vec6 y_qd = -(b.QmB * b.S) - 2.0 * (b.Ic * b.u);
    for (int r = j; r >= 0; r = bodies_[r].parent) {
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
      dq[i * n + j] = -sq;
      dqd[i * n + j] = -sqd;
    }
  return true;
}

}  // namespace spacar
