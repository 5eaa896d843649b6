// The recursive Newton–Euler algorithm of a planar tree written once on a scalar type S: double,
// or forward-mode dual numbers (autodiff.hpp) for the exact derivatives ∂τ/∂q and ∂τ/∂q̇
// (PlanarTree::dynamics_derivatives, rnea_derivatives.hpp). The same passes and conventions as
// PlanarAlgebra, ArticulatedTree::inverse_dynamics and PlanarTree::applied_loads
// (planar_tree.hpp, articulated.hpp, planar_tree.cpp): vectors (ω, vx, vy) in body coordinates at
// the body's pin; a hinge's q is its angle, a DYNX BETA's q the body's absolute rotation.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "spacar/autodiff.hpp"
#include "spacar/recursive/planar_tree.hpp"

namespace spacar::rnea {

template <class S>
using P3 = std::array<S, 3>;

// The pose of a body relative to its parent (c, s) and in the world (φ, cos φ, sin φ).
template <class S>
struct PlanarPose {
  S c, s, phi, cw, sw;
};

// X v: a parent's vector in the child's coordinates; Xᵀ g: a child's force in the parent's.
template <class S>
P3<S> planar_to_child(const Eigen::Vector2d& r, const S& c, const S& s, const P3<S>& v) {
  return {v[0], (s * r.x() - c * r.y()) * v[0] + c * v[1] + s * v[2], (c * r.x() + s * r.y()) * v[0] - s * v[1] + c * v[2]};
}
template <class S>
P3<S> planar_to_parent(const Eigen::Vector2d& r, const S& c, const S& s, const P3<S>& g) {
  return {g[0] + (s * r.x() - c * r.y()) * g[1] + (c * r.x() + s * r.y()) * g[2], c * g[1] - s * g[2], s * g[1] + c * g[2]};
}
template <class S>
P3<S> planar_times(const Eigen::Matrix3d& I, const P3<S>& x) {
  P3<S> out;
  for (int i = 0; i < 3; ++i) out[i] = I(i, 0) * x[0] + I(i, 1) * x[1] + I(i, 2) * x[2];
  return out;
}

// τ of ArticulatedTree<PlanarAlgebra>::inverse_dynamics at (q, q̇, q̈): the bodies, the ground's
// fictitious acceleration (−g), the loads (FORCE in world directions at body points, or a
// moment) and the springs and dampers of released hinges between bodies (−1: the ground).
template <class S, class Loads, class Springs>
void planar_inverse_dynamics(const std::vector<BodyModel<PlanarAlgebra>>& bodies, const Eigen::Vector3d& base,
                             const Loads& loads, const Springs& springs, const S* q, const S* qd, const S* qdd,
                             S* force) {
  const size_t nb = bodies.size();
  thread_local std::vector<PlanarPose<S>> pose;
  thread_local std::vector<P3<S>> v, a, f;
  thread_local std::vector<S> tau, u;
  pose.resize(nb);
  v.resize(nb);
  a.resize(nb);
  f.resize(nb);
  tau.resize(nb);
  u.resize(nb);
  for (size_t i = 0; i < nb; ++i) {  // outwards: poses, velocities, accelerations, I a + v ×* I v
    const BodyModel<PlanarAlgebra>& m = bodies[i];
    const bool root = m.parent < 0;
    S theta, ud, udd;
    if (m.absolute) {  // q: the body's rotation; the joint turns by q − φ_parent
      theta = q[m.dof] - m.offset - (root ? S(0.0) : pose[m.parent].phi);
      ud = qd[m.dof] - (root ? S(0.0) : v[m.parent][0]);
      tau[i] = S(0.0);
    } else {
      theta = m.sign * q[m.dof] + m.offset;
      ud = m.sign * qd[m.dof];
      tau[i] = -m.sign * (m.stiffness * q[m.dof] + m.damping * qd[m.dof]);
    }
    PlanarPose<S>& p = pose[i];
    p.c = cos(theta);
    p.s = sin(theta);
    if (root) {
      p.phi = theta;
      p.cw = p.c;
      p.sw = p.s;
    } else {
      const PlanarPose<S>& pp = pose[m.parent];
      p.phi = pp.phi + theta;
      p.cw = pp.cw * p.c - pp.sw * p.s;
      p.sw = pp.sw * p.c + pp.cw * p.s;
    }
    P3<S> vi = root ? P3<S>{S(0.0), S(0.0), S(0.0)} : planar_to_child(m.r, p.c, p.s, v[m.parent]);
    vi[0] = vi[0] + ud;
    const P3<S> parent_a = root ? P3<S>{S(base[0]), S(base[1]), S(base[2])} : a[m.parent];
    P3<S> ai = planar_to_child(m.r, p.c, p.s, parent_a);
    ai[1] = ai[1] + ud * vi[2];  // the bias (0, u̇ v_y, −u̇ v_x)
    ai[2] = ai[2] - ud * vi[1];
    udd = m.absolute ? qdd[m.dof] - ai[0] : m.sign * qdd[m.dof];
    ai[0] = ai[0] + udd;
    v[i] = vi;
    a[i] = ai;
    const P3<S> h = planar_times(m.inertia, vi), Ia = planar_times(m.inertia, ai);
    // I a + v ×* (I v) − the body-fixed load
    f[i] = {Ia[0] - vi[2] * h[1] + vi[1] * h[2] - m.load[0], Ia[1] - vi[0] * h[2] - m.load[1],
            Ia[2] + vi[0] * h[1] - m.load[2]};
  }
  for (const auto& sp : springs) {  // torque −σ on body b, +σ on body a
    auto angle = [&](int b, double beta0) { return b < 0 ? S(beta0) : beta0 + pose[b].phi; };
    auto rate = [&](int b) { return b < 0 ? S(0.0) : v[b][0]; };
    const S sigma = sp.stiffness * (angle(sp.body_b, sp.beta0_b) - angle(sp.body_a, sp.beta0_a)) +
                    sp.damping * (rate(sp.body_b) - rate(sp.body_a));
    if (sp.body_b >= 0) f[sp.body_b][0] = f[sp.body_b][0] + sigma;
    if (sp.body_a >= 0) f[sp.body_a][0] = f[sp.body_a][0] - sigma;
  }
  for (const auto& l : loads) {
    P3<S>& fb = f[l.body];
    if (l.component == 2) {  // a moment
      fb[0] = fb[0] - l.value;
      continue;
    }
    const double fx = l.component == 0 ? l.value : 0.0, fy = l.component == 1 ? l.value : 0.0;
    const PlanarPose<S>& p = pose[l.body];
    const S bx = p.cw * fx + p.sw * fy, by = -p.sw * fx + p.cw * fy;  // in body coordinates
    fb = {fb[0] - (l.b.x() * by - l.b.y() * bx), fb[1] - bx, fb[2] - by};
  }
  for (size_t i = 0; i < nb; ++i) u[i] = S(0.0);
  for (size_t i = nb; i-- > 0;) {  // inwards: the joint torques, the forces into the parents
    const BodyModel<PlanarAlgebra>& m = bodies[i];
    const S torque = f[i][0] - tau[i];
    const bool root = m.parent < 0;
    if (!root) {
      const P3<S> g = planar_to_parent(m.r, pose[i].c, pose[i].s, f[i]);
      P3<S>& fp = f[m.parent];
      fp = {fp[0] + g[0], fp[1] + g[1], fp[2] + g[2]};
    }
    if (m.absolute) {
      force[m.dof] = torque + u[i];
      if (!root) u[m.parent] = u[m.parent] - torque;
    } else {
      force[m.dof] = m.sign * (torque + u[i]);
      if (!root) u[m.parent] = u[m.parent] + u[i];
    }
  }
}

}  // namespace spacar::rnea

namespace spacar {

template <class S>
void PlanarTree::inverse_dynamics_on(const S* q, const S* qd, const S* qdd, S* force) const {
  rnea::planar_inverse_dynamics(bodies_, base_acceleration_, loads_, springs_, q, qd, qdd, force);
}

}  // namespace spacar
