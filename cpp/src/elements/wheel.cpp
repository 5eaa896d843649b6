// WHEEL (extension): a thin disc rolling without slip on a plane n·x = 0 or on a quadratic
// surface f(x) = 0 (formulation.md §4.14). p1: wheel centre, o1: wheel body, axle a = R(λ) â0,
// ω = 2 E(λ) λ̇ (global angular velocity). The contact point y is the rim point where f is least
// (on a plane the lowest rim point), N the unit normal there, t1 = (a × N)/|a × N|
// (longitudinal), t2 = N × t1 (lateral), v_c = ẋ_p1 + ω × (y − x_p1) its material velocity:
//   e1 = f(y)/|∇f(y)|       height of the contact point (holonomic; fixed: contact)
//   ė2 = t1 · v_c           longitudinal slip (velocity level)
//   ė3 = t2 · v_c           lateral slip (velocity level)
// On a plane these are e1 = n · x_p1 − r s, ė2 = t1 · ẋ_p1 − r a · ω, ė3 = t2 · ẋ_p1 + r s t1 · ω
// with s = √(1 − (n·a)²), evaluated in closed form. Knife-edge rolling: e1 fixed, e2 and e3 ENHC.
#include <cmath>
#include <limits>

#include "spacar/elements/registry.hpp"
#include "spacar/elements/spatial.hpp"

namespace spacar {
namespace {

template <class S>
Vec3<S> cross3(const Vec3<S>& a, const Vec3<S>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// ω = 2 E(λ) λ̇, the global angular velocity.
template <class S>
Vec3<S> angular_velocity(const S* l, const S* ld) {
  return {2.0 * (-l[1] * ld[0] + l[0] * ld[1] - l[3] * ld[2] + l[2] * ld[3]),
          2.0 * (-l[2] * ld[0] + l[3] * ld[1] + l[0] * ld[2] - l[1] * ld[3]),
          2.0 * (-l[3] * ld[0] - l[2] * ld[1] + l[1] * ld[2] + l[0] * ld[3])};
}

// f(x) = xᵀQx + bᵀx + c with the SURFACE coefficients c1..c10 (c1x² + c2y² + c3z² + c4xy +
// c5yz + c6zx + c7x + c8y + c9z + c10); positive on the wheel's side.
struct Quadric {
  Eigen::Matrix3d Q;
  Eigen::Vector3d b;
  double c;

  template <class S>
  S value(const Vec3<S>& x) const {
    S f = S(c);
    for (int i = 0; i < 3; ++i) {
      f = f + b[i] * x[i];
      for (int j = 0; j < 3; ++j) f = f + Q(i, j) * x[i] * x[j];
    }
    return f;
  }
  template <class S>
  Vec3<S> gradient(const Vec3<S>& x) const {
    Vec3<S> g;
    for (int i = 0; i < 3; ++i) g[i] = b[i] + 2.0 * (Q(i, 0) * x[0] + Q(i, 1) * x[1] + Q(i, 2) * x[2]);
    return g;
  }
};

class Wheel : public AutoDiffElement<Wheel, 7, 3> {
 public:
  static constexpr unsigned kVelocityRows = 0b110;

  explicit Wheel(const ElementSetup& s) {
    const auto& p = s.params;
    if (p.size() != 4 && p.size() != 7 && p.size() != 14)
      throw InputError("WHEEL needs ax ay az r, ax ay az r nx ny nz (plane) or ax ay az r c1 .. c10 (quadratic surface)");
    a0_ = Eigen::Vector3d(p[0], p[1], p[2]);
    r_ = p[3];
    if (!(a0_.norm() > 0.0)) throw InputError("WHEEL: the axle direction has zero length");
    if (!(r_ > 0.0)) throw InputError("WHEEL: the radius must be positive");
    a0_.normalize();
    if (p.size() == 14) {
      quadric_ = true;
      q_.Q << p[4], 0.5 * p[7], 0.5 * p[9], 0.5 * p[7], p[5], 0.5 * p[8], 0.5 * p[9], 0.5 * p[8], p[6];
      q_.b = Eigen::Vector3d(p[10], p[11], p[12]);
      q_.c = p[13];
      if (q_.Q.isZero(0.0) && q_.b.isZero(0.0)) throw InputError("WHEEL: the surface coefficients c1 .. c9 are all zero");
      // (u0, w0, â0) right-handed and orthonormal: the rim is x_p1 + r (cos φ u + sin φ w).
      Eigen::Index k;
      a0_.cwiseAbs().minCoeff(&k);
      u0_ = (Eigen::Vector3d::Unit(k) - a0_[k] * a0_).normalized();
      w0_ = a0_.cross(u0_);
    } else {
      n_ = p.size() == 7 ? Eigen::Vector3d(p[4], p[5], p[6]) : Eigen::Vector3d(0, 0, 1);
      if (!(n_.norm() > 0.0)) throw InputError("WHEEL: the ground-plane normal has zero length");
      n_.normalize();
    }
  }

  template <class S>
  void deform(const S* x, S* e) const {
    e[1] = S(0.0);
    e[2] = S(0.0);
    if (!quadric_) {
      const Vec3<S> a = rotate(x + 3, a0_);
      const S na = n_[0] * a[0] + n_[1] * a[1] + n_[2] * a[2];
      e[0] = n_[0] * x[0] + n_[1] * x[1] + n_[2] * x[2] - r_ * sqrt(1.0 - na * na);
      return;
    }
    const Vec3<S> y = contact_point(x);
    const Vec3<S> g = q_.gradient(y);
    e[0] = q_.value(y) / sqrt(dot3(g, g));
  }

  template <class S>
  void slip_rates(const S* x, const S* v, S* edot) const {
    const Vec3<S> a = rotate(x + 3, a0_);
    const Vec3<S> w = angular_velocity(x + 3, v + 3);
    const Vec3<S> xd = {v[0], v[1], v[2]};
    edot[0] = S(0.0);
    if (!quadric_) {
      const S na = n_[0] * a[0] + n_[1] * a[1] + n_[2] * a[2];
      const S s = sqrt(1.0 - na * na);
      const Vec3<S> n = {S(n_[0]), S(n_[1]), S(n_[2])};
      Vec3<S> t1 = cross3(a, n);
      for (S& t : t1) t = t / s;
      const Vec3<S> t2 = cross3(n, t1);
      edot[1] = dot3(t1, xd) - r_ * dot3(a, w);
      edot[2] = dot3(t2, xd) + r_ * s * dot3(t1, w);
      return;
    }
    const Vec3<S> y = contact_point(x);
    Vec3<S> n = q_.gradient(y);
    const S gn = sqrt(dot3(n, n));
    for (S& c : n) c = c / gn;
    Vec3<S> t1 = cross3(a, n);
    const S s = sqrt(dot3(t1, t1));
    for (S& t : t1) t = t / s;
    const Vec3<S> t2 = cross3(n, t1);
    const Vec3<S> arm = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
    const Vec3<S> wr = cross3(w, arm);
    const Vec3<S> vc = {xd[0] + wr[0], xd[1] + wr[1], xd[2] + wr[2]};
    edot[1] = dot3(t1, vc);
    edot[2] = dot3(t2, vc);
  }

 private:
  // Rim point at angle φ and the stationarity condition F(φ) = ∇f(y)·y' = 0 of f along the rim
  // with its derivative F' = y'ᵀ 2Q y' + ∇f·y'' (y'' = −(y − x_p1)).
  template <class S>
  void rim(const Vec3<S>& p, const Vec3<S>& u, const Vec3<S>& w, const S& phi, Vec3<S>& y, S& F, S& dF) const {
    const S c = cos(phi), s = sin(phi);
    Vec3<S> dy, ddy;
    for (int i = 0; i < 3; ++i) {
      y[i] = p[i] + r_ * (c * u[i] + s * w[i]);
      dy[i] = r_ * (c * w[i] - s * u[i]);
      ddy[i] = p[i] - y[i];
    }
    const Vec3<S> g = q_.gradient(y);
    F = dot3(g, dy);
    S dQd = S(0.0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) dQd = dQd + 2.0 * q_.Q(i, j) * dy[i] * dy[j];
    dF = dQd + dot3(g, ddy);
  }

  // Contact point: Newton on F(φ) in double from the lowest rim point over the tangent plane at
  // the centre, then two Newton steps in the scalar type S from the converged angle: each step
  // doubles the order of the exact derivatives carried by S (first and second derivatives).
  // NaN if there is no minimum of f on the rim near that start (the surface too curved for r).
  template <class S>
  Vec3<S> contact_point(const S* x) const {
    const Vec3<S> p = {x[0], x[1], x[2]}, u = rotate(x + 3, u0_), w = rotate(x + 3, w0_);
    double xv[7];
    for (int i = 0; i < 7; ++i) xv[i] = value_of(x[i]);
    const Vec3<double> pv = {xv[0], xv[1], xv[2]}, uv = rotate(xv + 3, u0_), wv = rotate(xv + 3, w0_);
    const Vec3<double> g0 = q_.gradient(pv);
    double phi = std::atan2(-dot3(g0, wv), -dot3(g0, uv));
    Vec3<double> yv;
    double F = 0.0, dF = 0.0, last = std::numeric_limits<double>::infinity();
    bool converged = false;
    for (int it = 0; it < 50 && !converged; ++it) {
      rim(pv, uv, wv, phi, yv, F, dF);
      if (!(dF > 0.0)) break;  // not at a minimum of f along the rim
      const double step = std::abs(F / dF);
      phi -= F / dF;
      // Converged, or at the round-off floor of F/dF (which grows like eps/|a × N| for a
      // steeply tilted disc): the steps in S below polish the angle anyway.
      converged = step < 1e-13 || (step < 1e-8 && step >= last);
      last = step;
    }
    if (!converged) phi = std::numeric_limits<double>::quiet_NaN();
    S ph = S(phi), Fs, dFs;
    Vec3<S> y;
    for (int k = 0; k < 2; ++k) {
      rim(p, u, w, ph, y, Fs, dFs);
      ph = ph - Fs / dFs;
    }
    rim(p, u, w, ph, y, Fs, dFs);
    return y;
  }

  Eigen::Vector3d a0_, n_, u0_, w0_;
  double r_;
  bool quadric_ = false;
  Quadric q_;
};

}  // namespace

ElementType wheel_element_type() {
  ElementType t = element_type<Wheel>(
      "WHEEL", {NodeKind::XYZ, NodeKind::Lambda}, {"p1", "o1"},
      {"height of the contact point", "longitudinal slip", "lateral slip"},
      "knife-edge wheel rolling on a plane or a quadratic surface (extension)");
  set_params(t, 4, 14,
             "ax ay az r [nx ny nz or c1 .. c10]: initial axle direction, radius; ground-plane normal "
             "(default 0 0 1) or the coefficients of a quadratic surface as for SURFACE, positive on the "
             "wheel's side");
  t.n_params_allowed = {4, 7, 14};
  t.extension = true;
  t.family = ElementFamily::Wheel;
  return t;
}

}  // namespace spacar
