// The passes of a spatial tree without a floating base written once on a scalar type S: double or
// forward-mode dual numbers (autodiff.hpp), for the exact derivatives of closed loops
// (closed_loop.cpp). The conventions of SpatialAlgebra and ArticulatedTree (spatial_tree.hpp,
// articulated.hpp): vectors (angular; linear) in body coordinates at the body's pin; a joint's q is
// its angle or slide u = sign q + offset; the ground's fictitious acceleration −g.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "spacar/autodiff.hpp"
#include "spacar/errors.hpp"
#include "spacar/recursive/spatial_tree.hpp"

namespace spacar::rnea {

template <class S>
using V3 = std::array<S, 3>;
template <class S>
using M3 = std::array<S, 9>;  // row major

template <class S>
V3<S> cross(const V3<S>& a, const V3<S>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class S>
S dot(const V3<S>& a, const V3<S>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template <class S>
V3<S> plus(const V3<S>& a, const V3<S>& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
template <class S>
V3<S> minus(const V3<S>& a, const V3<S>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
template <class S>
V3<S> times(const M3<S>& A, const V3<S>& x) {  // A x
  return {A[0] * x[0] + A[1] * x[1] + A[2] * x[2], A[3] * x[0] + A[4] * x[1] + A[5] * x[2],
          A[6] * x[0] + A[7] * x[1] + A[8] * x[2]};
}
template <class S>
V3<S> times_transposed(const M3<S>& A, const V3<S>& x) {  // Aᵀ x
  return {A[0] * x[0] + A[3] * x[1] + A[6] * x[2], A[1] * x[0] + A[4] * x[1] + A[7] * x[2],
          A[2] * x[0] + A[5] * x[1] + A[8] * x[2]};
}
template <class S>
M3<S> product(const M3<S>& A, const M3<S>& B) {
  M3<S> C;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
  return C;
}
template <class S>
V3<S> constant(const Eigen::Vector3d& x) {
  return {S(x[0]), S(x[1]), S(x[2])};
}

// A body's placement and motion on S.
template <class S>
struct SpatialMotion {
  M3<S> E, R;         // parent → body coordinates; body → world
  V3<S> r, pin;       // the pin from the parent's (parent coordinates); in the world
  V3<S> w, v;         // angular and linear velocity (body coordinates, at the pin)
  V3<S> alpha, acc;   // their accelerations
  S tau;              // the joint's spring and damper torque (−σ)
};

// Outwards (ArticulatedTree::outward and accelerate): placements, velocities and accelerations
// at (q, q̇, q̈) from the ground's acceleration `base` (world: angular; linear).
template <class S>
void spatial_outward(const std::vector<BodyModel<SpatialAlgebra>>& bodies, const Eigen::Matrix<double, 6, 1>& base,
                     const S* q, const S* qd, const S* qdd, std::vector<SpatialMotion<S>>& out) {
  out.resize(bodies.size());
  for (size_t i = 0; i < bodies.size(); ++i) {
    const BodyModel<SpatialAlgebra>& m = bodies[i];
    SpatialMotion<S>& b = out[i];
    const S theta = m.sign * q[m.dof] + m.offset, ud = m.sign * qd[m.dof], udd = m.sign * qdd[m.dof];
    b.tau = -m.sign * (m.stiffness * q[m.dof] + m.damping * qd[m.dof]);
    const V3<S> k = constant<S>(m.axis);
    b.r = constant<S>(m.r);
    M3<S> rel = {S(1.0), S(0.0), S(0.0), S(0.0), S(1.0), S(0.0), S(0.0), S(0.0), S(1.0)};  // body → parent
    if (m.prismatic) {
      for (int c = 0; c < 3; ++c) b.r[c] = b.r[c] + theta * m.axis[c];
    } else {  // Rodrigues (SpatialAlgebra::axis_rotation)
      const S c = cos(theta), s = sin(theta), one_c = 1.0 - c;
      rel = {c + one_c * k[0] * k[0], one_c * k[0] * k[1] - s * k[2], one_c * k[0] * k[2] + s * k[1],
             one_c * k[1] * k[0] + s * k[2], c + one_c * k[1] * k[1], one_c * k[1] * k[2] - s * k[0],
             one_c * k[2] * k[0] - s * k[1], one_c * k[2] * k[1] + s * k[0], c + one_c * k[2] * k[2]};
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) b.E[3 * r + c] = rel[3 * c + r];
    V3<S> w_p{S(0.0), S(0.0), S(0.0)}, v_p = w_p, alpha_p = constant<S>(base.head<3>()), acc_p = constant<S>(base.tail<3>());
    if (m.parent < 0) {
      b.R = rel;
      b.pin = b.r;
    } else {
      const SpatialMotion<S>& p = out[m.parent];
      b.R = product(p.R, rel);
      b.pin = plus(p.pin, times(p.R, b.r));
      w_p = p.w;
      v_p = p.v;
      alpha_p = p.alpha;
      acc_p = p.acc;
    }
    // to_child, then the joint's motion S u̇, its bias v ×ₘ S u̇ and its acceleration S ü.
    b.w = times(b.E, w_p);
    b.v = times(b.E, plus(v_p, cross(w_p, b.r)));
    b.alpha = times(b.E, alpha_p);
    b.acc = times(b.E, plus(acc_p, cross(alpha_p, b.r)));
    const V3<S> s{ud * m.axis[0], ud * m.axis[1], ud * m.axis[2]};
    const V3<S> sa{udd * m.axis[0], udd * m.axis[1], udd * m.axis[2]};
    if (m.prismatic) {
      b.v = plus(b.v, s);
      b.acc = plus(plus(b.acc, cross(b.w, s)), sa);
    } else {
      b.w = plus(b.w, s);
      b.alpha = plus(plus(b.alpha, cross(b.w, s)), sa);
      b.acc = plus(b.acc, cross(b.v, s));
    }
  }
}

// τ of ArticulatedTree<SpatialAlgebra>::forces at (q, q̇, q̈) with SpatialTree::applied_loads:
// the bodies, the ground's fictitious acceleration, world-direction loads F at body points b.
template <class S, class Loads>
void spatial_inverse_dynamics(const std::vector<BodyModel<SpatialAlgebra>>& bodies,
                              const Eigen::Matrix<double, 6, 1>& base, const Loads& loads, const S* q, const S* qd,
                              const S* qdd, S* force) {
  thread_local std::vector<SpatialMotion<S>> motion;
  thread_local std::vector<std::array<S, 6>> f;
  spatial_outward(bodies, base, q, qd, qdd, motion);
  const size_t nb = bodies.size();
  f.resize(nb);
  for (size_t i = 0; i < nb; ++i) {  // I a + v ×* I v − the body-fixed load
    const BodyModel<SpatialAlgebra>& m = bodies[i];
    const SpatialMotion<S>& b = motion[i];
    const std::array<S, 6> vel{b.w[0], b.w[1], b.w[2], b.v[0], b.v[1], b.v[2]};
    const std::array<S, 6> a{b.alpha[0], b.alpha[1], b.alpha[2], b.acc[0], b.acc[1], b.acc[2]};
    std::array<S, 6> h, Ia;
    for (int r = 0; r < 6; ++r) {
      h[r] = S(0.0);
      Ia[r] = S(0.0);
      for (int c = 0; c < 6; ++c) {
        h[r] = h[r] + m.inertia(r, c) * vel[c];
        Ia[r] = Ia[r] + m.inertia(r, c) * a[c];
      }
    }
    const V3<S> ha{h[0], h[1], h[2]}, hl{h[3], h[4], h[5]};
    const V3<S> top = plus(cross(b.w, ha), cross(b.v, hl)), bottom = cross(b.w, hl);
    for (int c = 0; c < 3; ++c) {
      f[i][c] = Ia[c] + top[c] - m.load[c];
      f[i][3 + c] = Ia[3 + c] + bottom[c] - m.load[3 + c];
    }
  }
  for (const auto& l : loads) {
    const V3<S> fb = times_transposed(motion[l.body].R, constant<S>(l.force));  // in body coordinates
    const V3<S> moment = cross(constant<S>(l.b), fb);
    for (int c = 0; c < 3; ++c) {
      f[l.body][c] = f[l.body][c] - moment[c];
      f[l.body][3 + c] = f[l.body][3 + c] - fb[c];
    }
  }
  for (size_t i = nb; i-- > 0;) {  // inwards: the joints' share, the rest into the parents
    const BodyModel<SpatialAlgebra>& m = bodies[i];
    const SpatialMotion<S>& b = motion[i];
    const int o = m.prismatic ? 3 : 0;
    const S torque = m.axis[0] * f[i][o] + m.axis[1] * f[i][o + 1] + m.axis[2] * f[i][o + 2] - b.tau;
    force[m.dof] = m.sign * torque;
    if (m.parent < 0) continue;
    const V3<S> fl = times_transposed(b.E, V3<S>{f[i][3], f[i][4], f[i][5]});
    const V3<S> fa = plus(times_transposed(b.E, V3<S>{f[i][0], f[i][1], f[i][2]}), cross(b.r, fl));
    for (int c = 0; c < 3; ++c) {
      f[m.parent][c] = f[m.parent][c] + fa[c];
      f[m.parent][3 + c] = f[m.parent][3 + c] + fl[c];
    }
  }
}

}  // namespace spacar::rnea

namespace spacar {

template <class S>
void SpatialTree::inverse_dynamics_on(const S* q, const S* qd, const S* qdd, S* force) const {
  // The passes have no floating base (loops on one are refused, the only callers).
  if (floating_) throw InputError("SpatialTree::inverse_dynamics_on: not written for a floating base");
  rnea::spatial_inverse_dynamics(bodies_, base_acceleration_, loads_, q, qd, qdd, force);
}

}  // namespace spacar
