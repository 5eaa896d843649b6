// BEAM and BEAMNL: spatial beam between p (XYZ), its orientation λp (LAMBDA), q and λq
// (formulation.md §4.8, §4.9). Reference frame C0 = [e_x0 e_y0 e_z0] (LGEOMY, 9 values):
// e_x0 the initial chord, e_y0 the principal y-axis of the cross-section. With the current
// triads e_j^p = R(λp) e_j0, e_j^q = R(λq) e_j0 and e_l the chord direction:
//   e1 = l − l0                                   elongation
//   e2 = l0 (e_z^p·e_y^q − e_y^p·e_z^q)/2          torsion (= l0 sin ψ)
//   e3 = +l0 (e_l·e_z^p),  e4 = −l0 (e_l·e_z^q)    bending about local y
//   e5 = −l0 (e_l·e_y^p),  e6 = +l0 (e_l·e_y^q)    bending about local z
// so that motion in the x–y plane with e_y0 = n(α0) reproduces PLBEAM: e5, e6 = PLBEAM e2, e3.
// BEAMNL adds (2e3² + e3e4 + 2e4² + 2e5² + e5e6 + 2e6²)/(30 l0) to e1.
// BEAMC (extension, exact for constant curvature and twist: circles and helices) measures the
// same deformations by angles. With the material frames M_p = R(λp) C0, M_q = R(λq) C0:
//   φ = log(M_pᵀ M_q)             the relative rotation vector (its components in both frames)
//   M_m = M_p exp(φ/2)            the mid frame; c = M_mᵀ (x_q − x_p) the chord in it
//   g = G(φ) e_x, G(φ) = ∫ exp(u φ̂) du over u in [−½, ½]   the chord of an arc of unit length
//                                  whose curvature and twist are φ (a helix) in that frame
//   β = the rotation vector from g to c   (the chord's departure from that arc)
//   e1 = |c|/|g| − l0 + l0 (βy² + βz²)/10   elongation along the arc
//   e2 = l0 φx;  e3, e4 = l0 (−φy/2 ∓ βy);  e5, e6 = l0 (−φz/2 ∓ βz)
// In the x–y plane it is PLBEAMC while the end sections turn by less than π relative to each
// other (one element of either can bend through less than a half turn; PLBEAMC's angles reach
// further); to first order at the straight reference it is BEAM.
// BEAMW (extension, warping torsion after Vlasov) is BEAM with the rate of twist at each end as a
// coordinate of its own (the warping nodes w1, w2: one coordinate each, placed after BEAM's four
// nodes) and two deformations more, the departure of the end rates from the mean twist:
//   e7 = l0 (l0 w1) − e2,  e8 = e2 − l0 (l0 w2)      (e2 = l0 ψ to first order)
// With the twist interpolated by the cubic of those end values and rates, the warping energy
// ½∫EIw ψ''² and the torsion ½∫GJ ψ'² give the pair EIw/l0⁵ [[4, −2], [−2, 4]] +
// GJ/(30 l0³) [[4, 1], [1, 4]] on (e7, e8) beside GJ/l0³ on e2 (e7/l0² is a rate of twist, where
// the bending deformations over l0 are angles). A warping node fixed restrains
// the section's warping (a clamp); free, the rates settle at the mean twist and the beam is BEAM.
// EMASS's fifth value ρIw gives the warping inertia ½∫ρIw ẇ² with w linear between the ends.
// Mass: the cubic Hermite interpolation with nodal tangents R(λ)e_x0 (as PLBEAM); rotary
// inertia of the cross-section only with the extension EMASS e rhoA rhoIp [rhoIy rhoIz].
#include <cmath>

#include "spacar/elements/registry.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"

namespace spacar {
namespace {

// Quaternions (w, x, y, z) of any scalar: a ⊗ b, and R(q)ᵀ v.
template <class S, class T>
std::array<S, 4> qmul(const std::array<S, 4>& a, const std::array<T, 4>& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}
template <class S>
Vec3<S> rotate_back(const std::array<S, 4>& q, const Vec3<S>& v) {  // R(q)ᵀ v = R(q̄) v
  const S w = q[0], x = -q[1], y = -q[2], z = -q[3];
  const S s = w * w - (x * x + y * y + z * z), lv = x * v[0] + y * v[1] + z * v[2];
  return {s * v[0] + 2.0 * x * lv + 2.0 * w * (y * v[2] - z * v[1]),
          s * v[1] + 2.0 * y * lv + 2.0 * w * (z * v[0] - x * v[2]),
          s * v[2] + 2.0 * z * lv + 2.0 * w * (x * v[1] - y * v[0])};
}
// atan2(√n2, w)/√n2 for w > 0 near n2 = 0 too (the series in n2/w², whose derivatives stay finite
// where √n2 has none: the straight reference).
template <class S>
S atan_ratio(const S& n2, const S& w) {
  const double r = value_of(n2) / (value_of(w) * value_of(w));
  if (value_of(w) > 0.0 && r < 1e-10) {
    const S t = n2 / (w * w);
    return (1.0 - t / 3.0 + t * t / 5.0) / w;
  }
  // (n2 = 0 with w < 0: the half turn, whose axis is undefined; kept finite, its vector is 0.)
  const S n = sqrt(value_of(n2) > 0.0 ? n2 : S(1e-300));
  return atan2(n, w) / n;
}

template <Bending Kind>
class Beam : public AutoDiffElement<Beam<Kind>, 14, 6, 4, 3> {
  using Base = AutoDiffElement<Beam<Kind>, 14, 6, 4, 3>;
  static constexpr bool Nonlinear = Kind == Bending::SineCorrected;
  static constexpr bool Arc = Kind == Bending::Arc;

 public:
  explicit Beam(const ElementSetup& s) : l0_(s.l0) {
    if (s.lgeomy.size() != 9)
      throw InputError(std::string(Arc ? "BEAMC" : Nonlinear ? "BEAMNL" : "BEAM") +
                       ": LGEOMY needs 9 values (e_x0, e_y0, e_z0), got " +
                       std::to_string(s.lgeomy.size()));
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) C0_(i, j) = s.lgeomy[3 * j + i];
    if constexpr (Arc) {  // its angles are those of the frame's rotation: it must be one
      if (!((C0_.transpose() * C0_ - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9 && C0_.determinant() > 0.0))
        throw InputError("BEAMC: LGEOMY must be a right-handed orthonormal frame (e_x0, e_y0, e_z0 = e_x0 × e_y0)");
      const Eigen::Quaterniond q0(C0_);
      c0_ = {q0.w(), q0.x(), q0.y(), q0.z()};
    }
    const double rhoA = s.emass.empty() ? 0.0 : s.emass[0];
    mass_ = hermite_mass<3>(rhoA, l0_);
    // Rotary inertia: T = (l0/6)(Ω_pᵀJΩ_p + Ω_pᵀJΩ_q + Ω_qᵀJΩ_q), Ω the section angular velocity.
    const Eigen::Vector3d Js(s.emass.size() > 1 ? s.emass[1] : 0.0, s.emass.size() > 2 ? s.emass[2] : 0.0,
                             s.emass.size() > 3 ? s.emass[3] : 0.0);
    rotary_ = Js.any();
    const Eigen::Matrix3d A = C0_ * Js.asDiagonal() * C0_.transpose();
    A_[0] = A_[3] = (l0_ / 3.0) * A;
    A_[1] = A_[2] = (l0_ / 6.0) * A;
  }

  template <class S>
  void deform(const S* x, S* e) const {
    if constexpr (Arc) return deform_arc(x, e);
    const S dx = x[7] - x[0], dy = x[8] - x[1], dz = x[9] - x[2];
    const S l = sqrt(dx * dx + dy * dy + dz * dz);
    const Vec3<S> el = {dx / l, dy / l, dz / l};
    const S* lp = x + 3;
    const S* lq = x + 10;
    const Vec3<S> yp = rotate(lp, C0_.col(1)), zp = rotate(lp, C0_.col(2));
    const Vec3<S> yq = rotate(lq, C0_.col(1)), zq = rotate(lq, C0_.col(2));
    e[1] = 0.5 * l0_ * (dot3(zp, yq) - dot3(yp, zq));
    e[2] = l0_ * dot3(el, zp);
    e[3] = -l0_ * dot3(el, zq);
    e[4] = -l0_ * dot3(el, yp);
    e[5] = l0_ * dot3(el, yq);
    e[0] = l - l0_;
    if constexpr (Nonlinear) e[0] += correction(e);
  }

  // Written out, with the values of deform(): the dual-number versions of the base cost several
  // times more, in every Newton iteration and output of a spatial model. The generic element
  // checks test these against finite differences like any other kernel's derivatives.
  void first_derivatives(const double* x, double* e, double* B) const override {
    if constexpr (Arc) return Base::first_derivatives(x, e, B);  // BEAMC: from the jets
    const Axes a = axes(x);
    Eigen::Map<Eigen::Matrix<double, 6, 14>> Bm(B);
    Bm.setZero();
    e[0] = a.l - l0_;
    Bm.block<1, 3>(0, 0) = -a.el.transpose();
    Bm.block<1, 3>(0, 7) = a.el.transpose();
    e[1] = 0.5 * l0_ * (a.zp.dot(a.yq) - a.yp.dot(a.zq));
    Bm.block<1, 4>(1, 3) = 0.5 * l0_ * (a.yq.transpose() * a.Jzp - a.zq.transpose() * a.Jyp);
    Bm.block<1, 4>(1, 10) = 0.5 * l0_ * (a.zp.transpose() * a.Jyq - a.yp.transpose() * a.Jzq);
    // Bending: e_i = k e_l·w with w a section axis of the node whose λ starts at column lam.
    auto bending = [&](int i, double k, const Eigen::Vector3d& w, const Mat34& Jw, int lam) {
      e[i] = k * a.el.dot(w);
      const Eigen::RowVector3d g = k * w.transpose() * a.P;
      Bm.block<1, 3>(i, 0) = -g;
      Bm.block<1, 3>(i, 7) = g;
      Bm.block<1, 4>(i, lam) = k * a.el.transpose() * Jw;
    };
    bending(2, l0_, a.zp, a.Jzp, 3);
    bending(3, -l0_, a.zq, a.Jzq, 10);
    bending(4, -l0_, a.yp, a.Jyp, 3);
    bending(5, l0_, a.yq, a.Jyq, 10);
    if constexpr (Nonlinear) {
      e[0] += correction(e);
      Bm.row(0) += ((4.0 * e[2] + e[3]) * Bm.row(2) + (e[2] + 4.0 * e[3]) * Bm.row(3) +
                    (4.0 * e[4] + e[5]) * Bm.row(4) + (e[4] + 4.0 * e[5]) * Bm.row(5)) /
                   (30.0 * l0_);
    }
  }

  // c = d²e/dt² at ẍ = 0: e_l and the section axes w = R(λ)c0 by their rates, with
  // ẅ = 2 R(λ̇)c0 (R(λ)c0 is quadratic in λ) and, of the chord, l̈ = (|ḋ|² − l̇²)/l and
  // ë_l = −(2 ė_l l̇ + e_l l̈)/l.
  void convective(const double* x, const double* v, double* c) const override {
    if constexpr (Arc) return Base::convective(x, v, c);
    const Axes a = axes(x);
    const Eigen::Vector3d dd(v[7] - v[0], v[8] - v[1], v[9] - v[2]);
    const double ld = a.el.dot(dd);
    const Eigen::Vector3d eld = (dd - ld * a.el) / a.l;
    const double ldd = (dd.squaredNorm() - ld * ld) / a.l;
    const Eigen::Vector3d eldd = -(2.0 * ld * eld + ldd * a.el) / a.l;
    const Eigen::Map<const Eigen::Vector4d> lpd(v + 3), lqd(v + 10);
    const Eigen::Vector3d ypd = a.Jyp * lpd, zpd = a.Jzp * lpd, yqd = a.Jyq * lqd, zqd = a.Jzq * lqd;
    const Eigen::Vector3d ypdd = 2.0 * rotated(v + 3, C0_.col(1)), zpdd = 2.0 * rotated(v + 3, C0_.col(2));
    const Eigen::Vector3d yqdd = 2.0 * rotated(v + 10, C0_.col(1)), zqdd = 2.0 * rotated(v + 10, C0_.col(2));
    c[0] = ldd;
    c[1] = 0.5 * l0_ * (dot_rates(a.zp, zpd, zpdd, a.yq, yqd, yqdd).second -
                        dot_rates(a.yp, ypd, ypdd, a.zq, zqd, zqdd).second);
    // Bending: e_i = k_i e_l·w_i.
    const double k[6] = {0.0, 0.0, l0_, -l0_, -l0_, l0_};
    const DotRates bend[6] = {{},
                              {},
                              dot_rates(a.el, eld, eldd, a.zp, zpd, zpdd),
                              dot_rates(a.el, eld, eldd, a.zq, zqd, zqdd),
                              dot_rates(a.el, eld, eldd, a.yp, ypd, ypdd),
                              dot_rates(a.el, eld, eldd, a.yq, yqd, yqdd)};
    double e[6] = {}, ed[6] = {};
    for (int i = 2; i < 6; ++i) {
      e[i] = k[i] * bend[i].value;
      ed[i] = k[i] * bend[i].rate;
      c[i] = k[i] * bend[i].second;
    }
    if constexpr (Nonlinear) {
      // f = 2a² + ab + 2b² per bending pair: f̈ = (4a + b) ä + (a + 4b) b̈ + 4ȧ² + 2ȧḃ + 4ḃ².
      double f = 0.0;
      for (int i : {2, 4})
        f += (4.0 * e[i] + e[i + 1]) * c[i] + (e[i] + 4.0 * e[i + 1]) * c[i + 1] + 4.0 * ed[i] * ed[i] +
             2.0 * ed[i] * ed[i + 1] + 4.0 * ed[i + 1] * ed[i + 1];
      c[0] += f / (30.0 * l0_);
    }
  }

  // Mass points x_p, l0 R(λp)e_x0, x_q, l0 R(λq)e_x0.
  template <class S>
  void mass_points(const S* x, S* g) const {
    const Vec3<S> tp = rotate(x + 3, C0_.col(0)), tq = rotate(x + 10, C0_.col(0));
    for (int i = 0; i < 3; ++i) {
      g[i] = x[i];
      g[3 + i] = l0_ * tp[i];
      g[6 + i] = x[7 + i];
      g[9 + i] = l0_ * tq[i];
    }
  }
  const MassPoints<4, 3>& mass_model() const { return mass_; }

  // The mass points' Jacobian and convective accelerations, written out (see point_derivatives).
  void point_jacobian(const double* x, const double* v, Eigen::Matrix<double, 12, 14>& Jg,
                      Eigen::Matrix<double, 12, 1>& gamma) const {
    Jg.setZero();
    gamma.setZero();
    Jg.block<3, 3>(0, 0).setIdentity();
    Jg.block<3, 4>(3, 3) = l0_ * rotate_jacobian(x + 3, C0_.col(0));
    Jg.block<3, 3>(6, 7).setIdentity();
    Jg.block<3, 4>(9, 10) = l0_ * rotate_jacobian(x + 10, C0_.col(0));
    gamma.segment<3>(3) = 2.0 * l0_ * rotated(v + 3, C0_.col(0));
    gamma.segment<3>(9) = 2.0 * l0_ * rotated(v + 10, C0_.col(0));
  }

  bool has_mass() const override { return Base::has_mass() || rotary_; }

  void mass(const double* x, const double* v, double* M, double* h) const override {
    Base::mass(x, v, M, h);
    add_rotary_inertia(x, v, M, h);
  }

  void mass_and_gravity(const double* x, const double* v, const double* g, double* M, double* h,
                        double* f) const override {
    Base::mass_and_gravity(x, v, g, M, h, f);
    add_rotary_inertia(x, v, M, h);
  }

  double kinetic_energy(const double* x, const double* v) const override {
    double T = Base::kinetic_energy(x, v);
    if (rotary_) {
      Eigen::MatrixXd M = Eigen::MatrixXd::Zero(14, 14);
      Eigen::VectorXd h = Eigen::VectorXd::Zero(14);
      add_rotary_inertia(x, v, M.data(), h.data());
      const Eigen::Map<const Eigen::VectorXd> vm(v, 14);
      T += 0.5 * vm.dot(M * vm);
    }
    return T;
  }

  // σ1 = (EA/l0) e1, σ2 = (GIp/l0³) e2, bending pairs (EI/l0³)[[4, −2], [−2, 4]]; with the shear
  // stiffnesses kGAy, kGAz (values 5 and 6; 0 or absent: shear-rigid) Timoshenko's pairs
  // (bending_pair): bending about y (EIy) shears along z (kGAz), about z (EIz) along y (kGAy).
  void constitutive(const std::vector<double>& v, double* S) const override {
    auto val = [&](size_t i) { return i < v.size() ? v[i] : 0.0; };
    Eigen::Map<Eigen::Matrix<double, 6, 6>> Sm(S);
    Sm.setZero();
    Sm(0, 0) = val(0) / l0_;
    Sm(1, 1) = val(1) / (l0_ * l0_ * l0_);
    for (int pair = 0; pair < 2; ++pair) {
      const BendingPair b = bending_pair(val(2 + pair), val(pair == 0 ? 5 : 4), l0_);
      const int a = 2 + 2 * pair;
      Sm(a, a) = Sm(a + 1, a + 1) = b.diagonal;
      Sm(a, a + 1) = Sm(a + 1, a) = b.coupling;
    }
  }

 private:
  using Mat34 = Eigen::Matrix<double, 3, 4>;
  // The chord and the section axes of both ends, with their Jacobians.
  struct Axes {
    Eigen::Vector3d el;  // chord direction
    double l;            // chord length
    Eigen::Matrix3d P;   // ∂e_l/∂(x_q − x_p) = (1 − e_l e_lᵀ)/l
    Eigen::Vector3d yp, zp, yq, zq;
    Mat34 Jyp, Jzp, Jyq, Jzq;
  };
  Axes axes(const double* x) const {
    Axes a;
    const Eigen::Vector3d d(x[7] - x[0], x[8] - x[1], x[9] - x[2]);
    a.l = d.norm();
    a.el = d / a.l;
    a.P = (Eigen::Matrix3d::Identity() - a.el * a.el.transpose()) / a.l;
    a.yp = rotated(x + 3, C0_.col(1));
    a.zp = rotated(x + 3, C0_.col(2));
    a.yq = rotated(x + 10, C0_.col(1));
    a.zq = rotated(x + 10, C0_.col(2));
    a.Jyp = rotate_jacobian(x + 3, C0_.col(1));
    a.Jzp = rotate_jacobian(x + 3, C0_.col(2));
    a.Jyq = rotate_jacobian(x + 10, C0_.col(1));
    a.Jzq = rotate_jacobian(x + 10, C0_.col(2));
    return a;
  }

  // BEAMC's deformations (see the top of the file).
  template <class S>
  void deform_arc(const S* x, S* e) const {
    const std::array<S, 4> lp = {x[3], x[4], x[5], x[6]}, lq = {x[10], x[11], x[12], x[13]};
    const std::array<S, 4> mp = qmul(lp, c0_), mq = qmul(lq, c0_);
    std::array<S, 4> r = qmul(std::array<S, 4>{mp[0], -mp[1], -mp[2], -mp[3]}, mq);  // M_pᵀ M_q
    // The rotations of the Euler parameters normalized (L2MIN1 holds them on the unit sphere).
    const double sign = value_of(r[0]) < 0.0 ? -1.0 : 1.0;  // the same rotation, by an angle below π
    const S rn = sign * sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    for (S& v : r) v = v / rn;
    const S n2 = r[1] * r[1] + r[2] * r[2] + r[3] * r[3];
    const S k = 2.0 * atan_ratio(n2, r[0]);
    const Vec3<S> phi = {k * r[1], k * r[2], k * r[3]};
    // The mid frame M_p exp(φ/2): the half rotation (1 + w, v̄) normalized.
    const S hn = sqrt((1.0 + r[0]) * (1.0 + r[0]) + n2);
    const std::array<S, 4> mm = qmul(mp, std::array<S, 4>{(1.0 + r[0]) / hn, r[1] / hn, r[2] / hn, r[3] / hn});
    const S mm2 = mm[0] * mm[0] + mm[1] * mm[1] + mm[2] * mm[2] + mm[3] * mm[3];  // |λp|²
    Vec3<S> c = rotate_back(mm, Vec3<S>{x[7] - x[0], x[8] - x[1], x[9] - x[2]});
    for (S& v : c) v = v / mm2;
    // g = G(φ) e_x = s1 e_x + s2 φ φx with s1 = 2 sin(a/2)/a, s2 = (1 − s1)/a², a = |φ|.
    const S a2 = dot3(phi, phi);
    S s1, s2;
    if (value_of(a2) < 1e-6) {
      s1 = 1.0 - a2 / 24.0 + a2 * a2 / 1920.0;
      s2 = 1.0 / 24.0 - a2 / 1920.0 + a2 * a2 / 322560.0;
    } else {
      const S a = sqrt(a2);
      s1 = 2.0 * sin(0.5 * a) / a;
      s2 = (1.0 - s1) / a2;
    }
    const Vec3<S> g = {s1 + s2 * phi[0] * phi[0], s2 * phi[0] * phi[1], s2 * phi[0] * phi[2]};
    // β: the rotation vector from g to c.
    const Vec3<S> gc = {g[1] * c[2] - g[2] * c[1], g[2] * c[0] - g[0] * c[2], g[0] * c[1] - g[1] * c[0]};
    const S kb = atan_ratio(dot3(gc, gc), dot3(g, c));
    const S by = kb * gc[1], bz = kb * gc[2];
    e[0] = sqrt(dot3(c, c) / dot3(g, g)) - l0_ + l0_ * (by * by + bz * bz) / 10.0;
    e[1] = l0_ * phi[0];
    e[2] = l0_ * (-0.5 * phi[1] - by);
    e[3] = l0_ * (-0.5 * phi[1] + by);
    e[4] = l0_ * (-0.5 * phi[2] - bz);
    e[5] = l0_ * (-0.5 * phi[2] + bz);
  }

  // BEAMNL's bending correction of the elongation.
  template <class S>
  S correction(const S* e) const {
    return (2.0 * e[2] * e[2] + e[2] * e[3] + 2.0 * e[3] * e[3] + 2.0 * e[4] * e[4] + e[4] * e[5] +
            2.0 * e[5] * e[5]) /
           (30.0 * l0_);
  }

  void add_rotary_inertia(const double* x, const double* v, double* M, double* h) const {
    if (!rotary_) return;
    const int lam[2] = {3, 10};
    add_rotational_inertia(14, x, v, lam, 2, A_, M, h);
  }

  double l0_;
  Eigen::Matrix3d C0_;
  std::array<double, 4> c0_{};  // C0 as a quaternion (BEAMC)
  MassPoints<4, 3> mass_;
  bool rotary_ = false;
  Eigen::Matrix3d A_[4];
};

// BEAMW: BEAM's coordinates and deformations (its first 14 and 6), and the warping rates w1, w2
// (coordinates 15, 16) with e7, e8. The mass and BEAM's stiffness are BEAM's.
class BeamW : public AutoDiffElement<BeamW, 16, 8, 4, 3> {
  using Base = AutoDiffElement<BeamW, 16, 8, 4, 3>;

 public:
  explicit BeamW(const ElementSetup& s)
      : beam_(checked(s)), l0_(s.l0), rhoIw_(s.emass.size() > 4 ? s.emass[4] : 0.0) {}

  template <class S>
  void deform(const S* x, S* e) const {
    beam_.deform(x, e);
    e[6] = l0_ * l0_ * x[14] - e[1];
    e[7] = e[1] - l0_ * l0_ * x[15];
  }

  // The mass of BEAM's 14 coordinates and the warping inertia of the rates.
  template <class S>
  void mass_points(const S* x, S* g) const {
    beam_.mass_points(x, g);
  }
  const MassPoints<4, 3>& mass_model() const { return beam_.mass_model(); }
  bool has_mass() const override { return beam_.has_mass() || rhoIw_ != 0.0; }
  void mass(const double* x, const double* v, double* M, double* h) const override {
    double M14[196], h14[14];
    beam_.mass(x, v, M14, h14);
    widen(M14, h14, M, h);
  }
  void mass_and_gravity(const double* x, const double* v, const double* g, double* M, double* h,
                        double* f) const override {
    double M14[196], h14[14], f14[14];
    beam_.mass_and_gravity(x, v, g, M14, h14, f14);
    widen(M14, h14, M, h);
    for (int i = 0; i < 16; ++i) f[i] = i < 14 ? f14[i] : 0.0;
  }
  void gravity(const double* x, const double* g, double* f) const override {
    beam_.gravity(x, g, f);
    f[14] = f[15] = 0.0;
  }
  double gravity_potential(const double* x, const double* g) const override { return beam_.gravity_potential(x, g); }
  double kinetic_energy(const double* x, const double* v) const override {
    const double k = rhoIw_ * l0_ / 6.0;
    return beam_.kinetic_energy(x, v) + k * (v[14] * v[14] + v[14] * v[15] + v[15] * v[15]);
  }

  // BEAM's σ = S e of e1 … e6 (ESTIFF values 1–6) and the warping pair of e7, e8 (EIw, the
  // seventh value, and GJ, the second).
  void constitutive(const std::vector<double>& v, double* S) const override {
    double S6[36];
    beam_.constitutive(std::vector<double>(v.begin(), v.begin() + std::min<size_t>(v.size(), 6)), S6);
    Eigen::Map<Eigen::Matrix<double, 8, 8>> Sm(S);
    Sm.setZero();
    Sm.topLeftCorner<6, 6>() = Eigen::Map<const Eigen::Matrix<double, 6, 6>>(S6);
    const double GJ = v.size() > 1 ? v[1] : 0.0, EIw = v.size() > 6 ? v[6] : 0.0, l3 = l0_ * l0_ * l0_;
    const double l5 = l3 * l0_ * l0_;
    Sm(6, 6) = Sm(7, 7) = 4.0 * EIw / l5 + 4.0 * GJ / (30.0 * l3);
    Sm(6, 7) = Sm(7, 6) = -2.0 * EIw / l5 + GJ / (30.0 * l3);
  }

 private:
  // BEAM's 14 × 14 mass and 14 inertia forces into the 16 coordinates, with the warping
  // inertia ρIw l0/6 [[2, 1], [1, 2]] of the rates (constant: no inertia force).
  void widen(const double* M14, const double* h14, double* M, double* h) const {
    Eigen::Map<Eigen::Matrix<double, 16, 16>> Mm(M);
    Mm.setZero();
    Mm.topLeftCorner<14, 14>() = Eigen::Map<const Eigen::Matrix<double, 14, 14>>(M14);
    const double k = rhoIw_ * l0_ / 6.0;
    Mm(14, 14) = Mm(15, 15) = 2.0 * k;
    Mm(14, 15) = Mm(15, 14) = k;
    for (int i = 0; i < 16; ++i) h[i] = i < 14 ? h14[i] : 0.0;
  }

  static const ElementSetup& checked(const ElementSetup& s) {  // (BEAM's message would name BEAM)
    if (s.lgeomy.size() != 9)
      throw InputError("BEAMW: LGEOMY needs 9 values (e_x0, e_y0, e_z0), got " + std::to_string(s.lgeomy.size()));
    return s;
  }

  Beam<Bending::Sine> beam_;
  double l0_, rhoIw_;
};

// LGEOMY (the frame C0, column by column) and LENGTHO from the reference geometry x = (p(3),
// λp(4), q(3), λq(4)); params: the initial direction of the cross-section's principal y-axis.
void reference_beam(const double* x, const std::vector<double>& params, double& l0, std::vector<double>& lgeomy) {
  const Eigen::Vector3d chord(x[7] - x[0], x[8] - x[1], x[9] - x[2]);
  l0 = chord.norm();
  if (!(l0 > 0.0)) return;  // the caller reports the zero length
  const Eigen::Matrix3d C = frame_from_axis(chord, Eigen::Vector3d(params[0], params[1], params[2]), "");
  lgeomy.assign(C.data(), C.data() + 9);
}

// What every spatial beam's catalogue row shares: the y-axis vector of its definition line, its
// length and frame (LGEOMY, from the first 14 coordinates), its drawing.
void spatial_beam_row(ElementType& t) {
  set_params(t, 3, 3, "x y z: initial direction of the principal y-axis of the cross-section");
  t.has_length = true;
  t.n_lgeomy = 9;
  t.has_direction = true;
  t.reference = reference_beam;
  t.family = ElementFamily::Beam;
}

template <Bending Kind>
ElementType beam_type() {
  const NodeKind p = NodeKind::XYZ, o = NodeKind::Lambda;
  static const char* const name[] = {"BEAM", "BEAMNL", "BEAMC"};
  static const char* const first[] = {"elongation", "bending-corrected elongation", "elongation along the arc"};
  static const char* const title[] = {"spatial beam", "spatial beam with bending-corrected elongation",
                                      "spatial beam exact for constant curvature and twist: bending and torsion "
                                      "angles, elongation along the helix (extension)"};
  const int k = static_cast<int>(Kind);
  ElementType t = element_type<Beam<Kind>>(
      name[k], {p, o, p, o}, {"p1", "o1", "p2", "o2"},
      {first[k], "torsion", "bending about local y at p1", "bending about local y at p2", "bending about local z at p1",
       "bending about local z at p2"},
      title[k]);
  t.extension = Kind == Bending::Arc;
  spatial_beam_row(t);
  set_stiffness(t, 6, "EA GIp EIy EIz kGAy kGAz");
  set_emass(t, 4, "rhoA [rhoIp rhoIy rhoIz] (rotary inertia: extension)");
  return t;
}

ElementType beamw_type() {
  const NodeKind p = NodeKind::XYZ, o = NodeKind::Lambda, w = NodeKind::Beta;
  ElementType t = element_type<BeamW>(
      "BEAMW", {p, o, p, o, w, w}, {"p1", "o1", "p2", "o2", "w1", "w2"},
      {"elongation", "torsion", "bending about local y at p1", "bending about local y at p2",
       "bending about local z at p1", "bending about local z at p2", "warping at p1", "warping at p2"},
      "spatial beam with warping torsion (Vlasov): the rates of twist at its ends as the one coordinate of the "
      "nodes w1, w2 (extension)");
  spatial_beam_row(t);
  set_stiffness(t, 7, "EA GIp EIy EIz kGAy kGAz EIw");
  set_emass(t, 5, "rhoA [rhoIp rhoIy rhoIz rhoIw]");
  t.extension = true;
  return t;
}

}  // namespace

ElementType beam_element_type() { return beam_type<Bending::Sine>(); }
ElementType beamnl_element_type() { return beam_type<Bending::SineCorrected>(); }
ElementType beamc_element_type() { return beam_type<Bending::Arc>(); }
ElementType beamw_element_type() { return beamw_type(); }

}  // namespace spacar
