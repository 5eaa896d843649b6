// PLBELT: open belt (tape) between two pulleys (formulation.md §4.6).
// p1, p2: pulley centres c1, c2; o1, o2: pulley rotations; radii r1, r2 on the definition line.
// The belt is wound counter-clockwise on pulley 1 and clockwise on pulley 2 from the contact
// points; the free span is the external tangent with both centres on its right:
//   d = c2 − c1, L = |d|, α its angle, δ = r2 − r1, l_f = √(L² − δ²) (span length),
//   s = t(α + asin(δ/L)) span direction, m = (s_y, −s_x), tangent points T_i = c_i − r_i m.
//   e1 = r1 β1 − r2 β2 + δ [α − α0 + asin(δ/L) − asin(δ/L0)] + l_f − l_f0
// (L0 = LENGTHO, α0 = LGEOMY, l_f0 = √(L0² − δ²)): the change of belt length between the two
// material end points. The angle α enters multiplied by δ, so e1 is defined up to 2π|δ|.
// Stiffness: σ1 = (EA/l_f0) e1. Mass (EMASS ρA a1 a2): each wound arc moves rigidly with its
// pulley, its angle a1 = a1⁰ + β1 − Δψ, a2 = a2⁰ − β2 + Δψ with Δψ = α − α0 + asin(δ/L) −
// asin(δ/L0); the span material velocity is linear between the tangent points.
#include <cmath>

#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class PlBelt : public AutoDiffElement<PlBelt, 6, 1> {
 public:
  explicit PlBelt(const ElementSetup& s) : l0_(s.l0) {
    if (s.params.size() != 2 || s.lgeomy.size() != 1) throw InputError("PLBELT needs r1 r2 and LGEOMY α0");
    r1_ = s.params[0];
    r2_ = s.params[1];
    delta_ = r2_ - r1_;
    alpha0_ = s.lgeomy[0];
    lf0_ = std::sqrt(l0_ * l0_ - delta_ * delta_);
    rhoA_ = s.emass.size() > 0 ? s.emass[0] : 0.0;
    a10_ = s.emass.size() > 1 ? s.emass[1] : 0.0;
    a20_ = s.emass.size() > 2 ? s.emass[2] : 0.0;
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const Geometry<S> g = geometry(x);
    e[0] = r1_ * x[2] - r2_ * x[5] + delta_ * g.dpsi + g.lf - lf0_;
  }

  double period(int) const override { return std::abs(delta_) > 0.0 ? 2.0 * M_PI * std::abs(delta_) : 0.0; }

  void constitutive(const std::vector<double>& v, double* S) const override { S[0] = v.empty() ? 0.0 : v[0] / lf0_; }

  bool has_distributed_mass() const { return rhoA_ > 0.0; }

  template <class S>
  S kinetic(const S* x, const S* v) const {
    const Geometry<S> g = geometry(x);
    S T = S(0.0);
    for (int i = 0; i < 2; ++i) {
      const Arc<S> arc = wound_arc(x, g, i);
      const S cx = v[3 * i], cy = v[3 * i + 1], w = v[3 * i + 2];
      const double r = i == 0 ? r1_ : r2_;
      // ½m|ċ|² + m ċ·(ω k × g) + ½ m r² ω²  for an arc rigid with its pulley
      T = T + 0.5 * arc.m * (cx * cx + cy * cy) + arc.m * w * (cx * (-arc.gy) + cy * arc.gx) +
          0.5 * arc.m * r * r * w * w;
    }
    // Span: material velocities at the tangent points, v_i = ċ_i − r_i β̇_i s, linear in between.
    const S v1x = v[0] - r1_ * v[2] * g.sx, v1y = v[1] - r1_ * v[2] * g.sy;
    const S v2x = v[3] - r2_ * v[5] * g.sx, v2y = v[4] - r2_ * v[5] * g.sy;
    return T + (rhoA_ * g.lf / 6.0) * (v1x * v1x + v1y * v1y + v1x * v2x + v1y * v2y + v2x * v2x + v2y * v2y);
  }

  template <class S>
  S potential(const S* x, const double* grav) const {
    const Geometry<S> g = geometry(x);
    S V = S(0.0);
    for (int i = 0; i < 2; ++i) {
      const Arc<S> arc = wound_arc(x, g, i);
      V = V - arc.m * (grav[0] * (x[3 * i] + arc.gx) + grav[1] * (x[3 * i + 1] + arc.gy));
    }
    // Span centre: the mean of the tangent points T_i = c_i − r_i m, m = (s_y, −s_x).
    const S mx = 0.5 * (x[0] + x[3]) - 0.5 * (r1_ + r2_) * g.sy;
    const S my = 0.5 * (x[1] + x[4]) + 0.5 * (r1_ + r2_) * g.sx;
    return V - rhoA_ * g.lf * (grav[0] * mx + grav[1] * my);
  }

 private:
  template <class S>
  struct Geometry {
    S lf, dpsi, sx, sy;
  };
  template <class S>
  struct Arc {
    S m, gx, gy;  // mass and centroid offset from the pulley centre
  };

  template <class S>
  Geometry<S> geometry(const S* x) const {
    const S dx = x[3] - x[0], dy = x[4] - x[1];
    const S L = sqrt(dx * dx + dy * dy);
    // Chord angle relative to the reference, continuous within ±π of it.
    const double c0 = std::cos(alpha0_), s0 = std::sin(alpha0_);
    const S dalpha = atan2(c0 * dy - s0 * dx, c0 * dx + s0 * dy);
    const S phi = asin(delta_ / L);
    const S psi = dalpha + alpha0_ + phi;
    return {sqrt(L * L - delta_ * delta_), dalpha + phi - std::asin(delta_ / l0_), cos(psi), sin(psi)};
  }

  // Wound arc on pulley i: from the contact point (direction −m from the centre), counter-
  // clockwise over a1 on pulley 1, clockwise over a2 on pulley 2.
  template <class S>
  Arc<S> wound_arc(const S* x, const Geometry<S>& g, int i) const {
    const double r = i == 0 ? r1_ : r2_;
    const S a = i == 0 ? a10_ + x[2] - g.dpsi : a20_ - x[5] + g.dpsi;
    // Unit vector to the contact point: −m = (−s_y, s_x); mid-arc direction rotated by ±a/2.
    const S half = 0.5 * a;
    const S ch = cos(half), sh = sin(half), sign = S(i == 0 ? 1.0 : -1.0);
    const S ux = -g.sy * ch - sign * g.sx * sh, uy = g.sx * ch - sign * g.sy * sh;
    // Centroid of a circular arc of angle a: r sin(a/2)/(a/2) along the mid direction.
    const S factor = value_of(half) == 0.0 ? S(r) : r * sh / half;
    return {rhoA_ * r * a, factor * ux, factor * uy};
  }

  double l0_, r1_, r2_, delta_, alpha0_, lf0_, rhoA_, a10_, a20_;
};

void reference_plbelt(const double* x, const std::vector<double>& params, double& l0, std::vector<double>& lgeomy) {
  l0 = std::hypot(x[3] - x[0], x[4] - x[1]);
  if (!(l0 > std::abs(params[1] - params[0])))
    throw InputError("the pulley centres are closer than the difference of the radii: no open belt");
  lgeomy = {std::atan2(x[4] - x[1], x[3] - x[0])};
}

}  // namespace

ElementType plbelt_element_type() {
  const NodeKind p = NodeKind::XY, o = NodeKind::Beta;
  ElementType t = element_type<PlBelt>("PLBELT", {p, o, p, o}, {"p1", "o1", "p2", "o2"}, {"belt elongation"},
                                       "planar belt");
  set_params(t, 2, 2, "r1 r2: radii of pulley 1 and pulley 2");
  set_stiffness(t, 1, "EA");
  set_emass(t, 3, "rhoA a1 a2 (belt wound on the pulleys: a1*r1 and a2*r2)");
  t.signed_emass_extras = true;
  t.has_length = true;
  t.n_lgeomy = 1;
  t.reference = reference_plbelt;
  t.family = ElementFamily::Belt;
  return t;
}

}  // namespace spacar
