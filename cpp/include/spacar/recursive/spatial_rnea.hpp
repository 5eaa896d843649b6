// The recursive Newton–Euler algorithm of a spatial tree written once on a scalar type S: double
// for the inverse dynamics, forward-mode dual numbers (autodiff.hpp) for its exact derivatives
// ∂τ/∂q and ∂τ/∂q̇ (SpatialTree::dynamics_derivatives). The same passes and conventions as
// SpatialAlgebra and ArticulatedTree::inverse_dynamics (spatial_tree.hpp, articulated.hpp):
// vectors (angular; linear) in body coordinates at the body's pin.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "spacar/autodiff.hpp"
#include "spacar/recursive/spatial_tree.hpp"

namespace spacar::rnea {

// The small operations inlined into the passes (the compiler would call them for dual numbers).
#define SPACAR_INLINE [[gnu::always_inline]] inline

template <class S>
struct V3 {
  std::array<S, 3> v{};
  S& operator[](int i) { return v[i]; }
  const S& operator[](int i) const { return v[i]; }
};
template <class S>
SPACAR_INLINE V3<S> operator+(const V3<S>& a, const V3<S>& b) { return {{a[0] + b[0], a[1] + b[1], a[2] + b[2]}}; }
template <class S>
SPACAR_INLINE V3<S> operator-(const V3<S>& a, const V3<S>& b) { return {{a[0] - b[0], a[1] - b[1], a[2] - b[2]}}; }
template <class S, class K>
SPACAR_INLINE V3<S> operator*(const K& k, const V3<S>& a) { return {{k * a[0], k * a[1], k * a[2]}}; }
template <class S>
SPACAR_INLINE V3<S> cross(const V3<S>& a, const V3<S>& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}
template <class S>
V3<S> lift(const Eigen::Vector3d& a) { return {{S(a[0]), S(a[1]), S(a[2])}}; }
template <class S>
S dot(const Eigen::Vector3d& a, const V3<S>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// A rotation (3 × 3, row major).
template <class S>
struct M3 {
  std::array<S, 9> m{};
  SPACAR_INLINE V3<S> operator*(const V3<S>& x) const {
    return {{m[0] * x[0] + m[1] * x[1] + m[2] * x[2], m[3] * x[0] + m[4] * x[1] + m[5] * x[2],
             m[6] * x[0] + m[7] * x[1] + m[8] * x[2]}};
  }
  SPACAR_INLINE V3<S> transposed_times(const V3<S>& x) const {
    return {{m[0] * x[0] + m[3] * x[1] + m[6] * x[2], m[1] * x[0] + m[4] * x[1] + m[7] * x[2],
             m[2] * x[0] + m[5] * x[1] + m[8] * x[2]}};
  }
  M3 operator*(const M3& b) const {
    M3 c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c.m[3 * i + j] = m[3 * i] * b.m[j] + m[3 * i + 1] * b.m[3 + j] + m[3 * i + 2] * b.m[6 + j];
    return c;
  }
};

// A motion or force vector (angular; linear).
template <class S>
struct Spatial {
  V3<S> w, l;
};

// I x for a constant 6 × 6 inertia (about the pin, body coordinates).
template <class S>
SPACAR_INLINE Spatial<S> times(const Eigen::Matrix<double, 6, 6>& I, const Spatial<S>& x) {
  Spatial<S> out;
  for (int i = 0; i < 6; ++i) {
    S sum = S(0.0);
    for (int j = 0; j < 3; ++j) sum = sum + I(i, j) * x.w[j] + I(i, 3 + j) * x.l[j];
    (i < 3 ? out.w[i] : out.l[i - 3]) = sum;
  }
  return out;
}

// The body's pose relative to its parent: E (parent → body coordinates), its transpose, the pin
// from the parent's r, and the rotation R (body → world).
template <class S>
struct Pose {
  M3<S> rel, R;  // rel: body → parent (E = relᵀ)
  V3<S> r;
};

// (τ of ArticulatedTree::inverse_dynamics) at (q, q̇, q̈) for the bodies, the ground's fictitious
// acceleration and the constant world-direction loads (body, point b, force).
template <class S, class Loads>
void inverse_dynamics(const std::vector<BodyModel<SpatialAlgebra>>& bodies, const Eigen::Matrix<double, 6, 1>& base,
                      const Loads& loads, const S* q, const S* qd, const S* qdd, S* force) {
  const size_t nb = bodies.size();
  // The work of one pass, kept between the calls of a thread (a batch calls it 3n + 2 times a state).
  thread_local std::vector<Pose<S>> pose;
  thread_local std::vector<Spatial<S>> v, a, f;
  thread_local std::vector<S> tau;
  pose.resize(nb);
  v.resize(nb);
  a.resize(nb);
  f.resize(nb);
  tau.resize(nb);
  const Spatial<S> ground_a{lift<S>(base.head<3>()), lift<S>(base.tail<3>())};
  for (size_t i = 0; i < nb; ++i) {
    const BodyModel<SpatialAlgebra>& m = bodies[i];
    const S theta = m.sign * q[m.dof] + m.offset, ud = m.sign * qd[m.dof], udd = m.sign * qdd[m.dof];
    tau[i] = -m.sign * (m.stiffness * q[m.dof] + m.damping * qd[m.dof]);
    Pose<S>& p = pose[i];
    p.r = lift<S>(m.r);
    const V3<S> k = lift<S>(m.axis);
    for (int j = 0; j < 9; ++j) p.rel.m[j] = S(j % 4 == 0 ? 1.0 : 0.0);
    if (m.prismatic) {
      p.r = p.r + theta * k;
    } else {
      const S c = cos(theta), s = sin(theta), one_c = 1.0 - c;
      p.rel.m = {c + one_c * k[0] * k[0], one_c * k[0] * k[1] - s * k[2], one_c * k[0] * k[2] + s * k[1],
                 one_c * k[1] * k[0] + s * k[2], c + one_c * k[1] * k[1], one_c * k[1] * k[2] - s * k[0],
                 one_c * k[2] * k[0] - s * k[1], one_c * k[2] * k[1] + s * k[0], c + one_c * k[2] * k[2]};
    }
    const bool root = m.parent < 0;
    p.R = root ? p.rel : pose[m.parent].R * p.rel;
    // to_child of the parent's velocity and acceleration: (E ω; E (v + ω × r)).
    auto to_child = [&](const Spatial<S>& x) {
      return Spatial<S>{p.rel.transposed_times(x.w), p.rel.transposed_times(x.l + cross(x.w, p.r))};
    };
    const V3<S> s_axis = ud * k;
    Spatial<S> vi = root ? Spatial<S>{} : to_child(v[m.parent]);
    (m.prismatic ? vi.l : vi.w) = (m.prismatic ? vi.l : vi.w) + s_axis;
    Spatial<S> bias;
    if (m.prismatic) bias.l = cross(vi.w, s_axis);
    else bias = {cross(vi.w, s_axis), cross(vi.l, s_axis)};
    Spatial<S> ai = to_child(root ? ground_a : a[m.parent]);
    ai = {ai.w + bias.w, ai.l + bias.l};
    (m.prismatic ? ai.l : ai.w) = (m.prismatic ? ai.l : ai.w) + udd * k;
    v[i] = vi;
    a[i] = ai;
    const Spatial<S> h = times(m.inertia, vi), Ia = times(m.inertia, ai);
    // I a + v ×* (I v) − the body-fixed load
    f[i].w = Ia.w + cross(vi.w, h.w) + cross(vi.l, h.l) - lift<S>(m.load.head<3>());
    f[i].l = Ia.l + cross(vi.w, h.l) - lift<S>(m.load.tail<3>());
  }
  for (const auto& load : loads) {  // constant world directions: Rᵀ F at the point b
    const V3<S> fb = pose[load.body].R.transposed_times(lift<S>(load.force));
    f[load.body].w = f[load.body].w - cross(lift<S>(load.b), fb);
    f[load.body].l = f[load.body].l - fb;
  }
  for (size_t i = nb; i-- > 0;) {
    const BodyModel<SpatialAlgebra>& m = bodies[i];
    force[m.dof] = m.sign * (dot(m.axis, m.prismatic ? f[i].l : f[i].w) - tau[i]);
    if (m.parent < 0) continue;
    const Pose<S>& p = pose[i];
    const V3<S> lin = p.rel * f[i].l;  // to_parent: (Eᵀ g_w + r × Eᵀ g_l; Eᵀ g_l)
    f[m.parent].w = f[m.parent].w + p.rel * f[i].w + cross(p.r, lin);
    f[m.parent].l = f[m.parent].l + lin;
  }
}

#undef SPACAR_INLINE

}  // namespace spacar::rnea
