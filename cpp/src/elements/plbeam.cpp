// PLBEAM and PLBEAMNL: planar beam between p (x, y), its rotation βp, q (x, y) and βq.
// Formulation (verified against the manual's slider-crank, see docs/formulation.md):
//   φp = α0 + βp, φq = α0 + βq  material tangent angles (α0: reference chord angle, LGEOMY)
//   e1 = l − l0                                   elongation
//   e2 = −l0 (e_l · n_p) = l0 sin(φp − α)         bending at p (length units)
//   e3 = +l0 (e_l · n_q) = l0 sin(α − φq)         bending at q
// PLBEAMNL adds the bending correction (2e2² + e2e3 + 2e3²)/(30 l0) to e1: the excess of the
// arc length of the cubic deflection over the chord.
// PLBEAMC (extension, exact for constant curvature) bends by the angles instead of their sines
// and measures the elongation along the arc:
//   e2 = l0 δp, δp = φp − α;  e3 = l0 δq, δq = α − φq  (angles in (−π, π])
//   e1 = l δm / sin δm − l0 + b² / (10 l0),  δm = (δp + δq)/2, b = (e2 − e3)/2
// A circular arc (δp = δq) is the chord l = 2R sin δm of the arc 2R δm: e1 is its stretch, and
// a pure moment rolls any mesh into the exact circle; b²/(10 l0) is PLBEAMNL's correction for the
// antisymmetric (S-shaped) part, to which the symmetric part's l δm²/6 adds its own second order.
// Mass: consistent mass of the cubic Hermite interpolation with the nodal material tangents.
#include <cmath>

#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

template <Bending Kind>
class PlBeam : public AutoDiffElement<PlBeam<Kind>, 6, 3, 4, 2> {
  static constexpr bool Nonlinear = Kind == Bending::SineCorrected;
  static constexpr bool Arc = Kind == Bending::Arc;
  using Base = AutoDiffElement<PlBeam<Kind>, 6, 3, 4, 2>;

 public:
  explicit PlBeam(const ElementSetup& s) : l0_(s.l0), alpha0_(s.lgeomy.empty() ? 0.0 : s.lgeomy[0]) {
    const double rhoA = s.emass.empty() ? 0.0 : s.emass[0];
    mass_ = hermite_mass<2>(rhoA, l0_);
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const S dx = x[3] - x[0], dy = x[4] - x[1];
    const S l = sqrt(dx * dx + dy * dy);
    const S phip = alpha0_ + x[2], phiq = alpha0_ + x[5];
    if constexpr (Arc) {
      const S dp = atan2(dx * sin(phip) - dy * cos(phip), dx * cos(phip) + dy * sin(phip));  // φp − α
      const S dq = atan2(dy * cos(phiq) - dx * sin(phiq), dx * cos(phiq) + dy * sin(phiq));  // α − φq
      e[1] = l0_ * dp;
      e[2] = l0_ * dq;
      const S b = 0.5 * (e[1] - e[2]);
      e[0] = l * arc_over_chord(0.5 * (dp + dq)) - l0_ + b * b / (10.0 * l0_);
      return;
    }
    // e_l · n(φ) = (−dx sin φ + dy cos φ) / l
    e[1] = -l0_ * (dy * cos(phip) - dx * sin(phip)) / l;
    e[2] = l0_ * (dy * cos(phiq) - dx * sin(phiq)) / l;
    e[0] = l - l0_;
    if constexpr (Nonlinear) e[0] += bending_elongation(e[1], e[2]);
  }

  // The same first derivatives written out (the hot path of Newton's method, where the jets took
  // twice as long): with d = x_q − x_p, l = |d|, t = d / l and the normals n = (−sin φ, cos φ),
  // u = d · n: ∂e1/∂d = t, ∂e2/∂d = −(l0 / l)(n_p − (u_p / l) t), ∂e2/∂φp = (l0 / l) d · (cos φp, sin φp),
  // and e3 likewise at q with the opposite sign.
  void first_derivatives(const double* x, double* e, double* B) const override {
    if constexpr (Arc) return Base::first_derivatives(x, e, B);  // PLBEAMC: from the jets
    const double dx = x[3] - x[0], dy = x[4] - x[1];
    const double l = std::sqrt(dx * dx + dy * dy), inv = 1.0 / l;
    const double tx = dx * inv, ty = dy * inv, k = l0_ * inv;
    const double sp = std::sin(alpha0_ + x[2]), cp = std::cos(alpha0_ + x[2]);
    const double sq = std::sin(alpha0_ + x[5]), cq = std::cos(alpha0_ + x[5]);
    const double up = dy * cp - dx * sp, uq = dy * cq - dx * sq;
    e[0] = l - l0_;
    e[1] = -k * up;
    e[2] = k * uq;
    // ∂e/∂d per deformation (the x_q columns, the x_p ones with the opposite sign), then ∂e/∂φ;
    // B is 3 × 6, column-major.
    const double rows[3][2] = {{tx, ty},
                               {k * (sp + up * inv * tx), -k * (cp - up * inv * ty)},
                               {-k * (sq + uq * inv * tx), k * (cq - uq * inv * ty)}};
    for (int a = 0; a < 3; ++a) {
      B[a + 0] = -rows[a][0];
      B[a + 3] = -rows[a][1];
      B[a + 9] = rows[a][0];
      B[a + 12] = rows[a][1];
      B[a + 6] = 0.0;
      B[a + 15] = 0.0;
    }
    B[1 + 6] = k * (dx * cp + dy * sp);
    B[2 + 15] = -k * (dx * cq + dy * sq);
    if constexpr (Nonlinear) {
      // e1 += (2 e2² + e2 e3 + 2 e3²) / (30 l0)
      const double g2 = (4.0 * e[1] + e[2]) / (30.0 * l0_), g3 = (e[1] + 4.0 * e[2]) / (30.0 * l0_);
      e[0] += bending_elongation(e[1], e[2]);
      for (int j = 0; j < 6; ++j) B[3 * j] += g2 * B[1 + 3 * j] + g3 * B[2 + 3 * j];
    }
  }

  // G = Σ σ_a ∂²e_a/∂x² written out (the static tangent and the linearization assemble it for
  // every element at every Newton iteration; the nested jets cost 20 times more). In the
  // variables (d, φp, φq), d = x_q − x_p: with g(d, φ) = (l0/l) d·n(φ), n = (−sin φ, cos φ),
  // m = (cos φ, sin φ), u = d·n, t = d/l,
  //   ∂²g/∂d² = (l0/l²)[(3 t tᵀ − I) u/l − (n tᵀ + t nᵀ)],  ∂²g/∂d∂φ = −(l0/l)(m − (t·m) t),
  //   ∂²g/∂φ² = −(l0/l) u,  and ∂²l/∂d² = (I − t tᵀ)/l;
  // e2 = −g(d, φp), e3 = g(d, φq); PLBEAMNL's elongation adds the bending term's Hessian.
  void stress_hessian(const double* x, const double* sigma, double* G) const override {
    if constexpr (Arc) return Base::stress_hessian(x, sigma, G);
    const double dx = x[3] - x[0], dy = x[4] - x[1];
    const double l = std::sqrt(dx * dx + dy * dy), inv = 1.0 / l;
    const Eigen::Vector2d d(dx, dy), t = d * inv;
    const double k = l0_ * inv;
    // Per end: n, m, u; the gradient of g in (d, φ) and its Hessian blocks.
    struct End {
      Eigen::Vector2d n, m, gd;   // gd = ∂g/∂d
      double u, gphi;            // gphi = ∂g/∂φ
      Eigen::Matrix2d hdd;
      Eigen::Vector2d hdphi;
      double hphiphi;
    };
    auto end = [&](double phi) {
      End e;
      e.n << -std::sin(phi), std::cos(phi);
      e.m << std::cos(phi), std::sin(phi);
      e.u = d.dot(e.n);
      e.gd = k * (e.n - e.u * inv * t);
      e.gphi = -k * d.dot(e.m);
      e.hdd = (k * inv) * ((3.0 * t * t.transpose() - Eigen::Matrix2d::Identity()) * (e.u * inv) -
                           (e.n * t.transpose() + t * e.n.transpose()));
      e.hdphi = -k * (e.m - t.dot(e.m) * t);
      e.hphiphi = -k * e.u;
      return e;
    };
    const End p = end(alpha0_ + x[2]), q = end(alpha0_ + x[5]);
    // The Hessian in (dx, dy, φp, φq): σ1 ∇²e1 + σ2 ∇²e2 + σ3 ∇²e3, e2 = −g_p, e3 = g_q.
    double s1 = sigma[0], s2 = sigma[1], s3 = sigma[2];
    Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
    H.topLeftCorner<2, 2>() = s1 * (Eigen::Matrix2d::Identity() - t * t.transpose()) * inv;
    if constexpr (Nonlinear) {
      // e1 += c(e2, e3) = (2 e2² + e2 e3 + 2 e3²)/(30 l0): ∇²c = c22 ∇e2∇e2ᵀ + c23 (∇e2∇e3ᵀ +
      // ∇e3∇e2ᵀ) + c33 ∇e3∇e3ᵀ + ∂c/∂e2 ∇²e2 + ∂c/∂e3 ∇²e3.
      const double e2 = -k * p.u, e3 = k * q.u, w = 1.0 / (30.0 * l0_);
      Eigen::Vector4d g2, g3;
      g2 << -p.gd, -p.gphi, 0.0;
      g3 << q.gd, 0.0, q.gphi;
      H += s1 * w * (4.0 * g2 * g2.transpose() + g2 * g3.transpose() + g3 * g2.transpose() + 4.0 * g3 * g3.transpose());
      s2 += s1 * w * (4.0 * e2 + e3);
      s3 += s1 * w * (e2 + 4.0 * e3);
    }
    // −s2 ∇²g_p + s3 ∇²g_q.
    H.topLeftCorner<2, 2>() += -s2 * p.hdd + s3 * q.hdd;
    H.block<2, 1>(0, 2) += -s2 * p.hdphi;
    H.block<2, 1>(0, 3) += s3 * q.hdphi;
    H(2, 2) += -s2 * p.hphiphi;
    H(3, 3) += s3 * q.hphiphi;
    H.block<1, 2>(2, 0) = H.block<2, 1>(0, 2).transpose();
    H.block<1, 2>(3, 0) = H.block<2, 1>(0, 3).transpose();
    // To x = (x_p, y_p, βp, x_q, y_q, βq): d = x_q − x_p, φp = α0 + βp, φq = α0 + βq.
    Eigen::Map<Eigen::Matrix<double, 6, 6>> Gm(G);
    static const int where[6] = {0, 1, 2, 0, 1, 3};        // (dx, dy, φp, dx, dy, φq)
    static const double sign[6] = {-1.0, -1.0, 1.0, 1.0, 1.0, 1.0};
    for (int b = 0; b < 6; ++b)
      for (int a = 0; a < 6; ++a) Gm(a, b) = sign[a] * sign[b] * H(where[a], where[b]);
  }

  // The inverse of deform() for one end: l = l0 + e1 (less PLBEAMNL's bending elongation), the
  // chord angle α from the known end's tangent angle and its bending deformation
  // (e2 = l0 sin(φp − α), e3 = l0 sin(α − φq)), then the other end's position and tangent angle.
  // Each bend δ (φp − α, α − φq) is taken on the arcsine's branch (below or above π/2) and the
  // turn of the guess's δ; the solved rotation then follows the known one continuously, however
  // far that has turned since the guess.
  bool has_closed_form() const override { return !Arc; }
  bool solve_end(int end, const double* e, const double* guess, double* x) const override {
    if constexpr (Arc) return false;
    const double l = l0_ + e[0] - (Nonlinear ? bending_elongation(e[1], e[2]) : 0.0);
    if (!(l > 0.0) || !(std::abs(e[1]) <= l0_) || !(std::abs(e[2]) <= l0_)) return false;
    const double guess_alpha = std::atan2(guess[4] - guess[1], guess[3] - guess[0]);
    auto bend = [&](double value, double guess_delta) {
      const double d0 = std::asin(value / l0_);
      const double d = std::cos(guess_delta) >= 0.0 ? d0 : M_PI - d0;
      return d + 2.0 * M_PI * std::round((guess_delta - d) / (2.0 * M_PI));
    };
    const double delta_p = bend(e[1], alpha0_ + guess[2] - guess_alpha);  // φp − α
    const double delta_q = bend(e[2], guess_alpha - alpha0_ - guess[5]);  // α − φq
    if (end == 1) {
      const double alpha = alpha0_ + x[2] - delta_p;
      x[3] = x[0] + l * std::cos(alpha);
      x[4] = x[1] + l * std::sin(alpha);
      x[5] = x[2] - delta_p - delta_q;
    } else {
      const double alpha = alpha0_ + x[5] + delta_q;
      x[0] = x[3] - l * std::cos(alpha);
      x[1] = x[4] - l * std::sin(alpha);
      x[2] = x[5] + delta_q + delta_p;
    }
    return std::isfinite(x[0] + x[1] + x[2] + x[3] + x[4] + x[5]);
  }

  // Mass points: x_p, l0 t_p, x_q, l0 t_q (position field r = H1 x_p + H2 l0 t_p + H3 x_q + H4 l0 t_q).
  template <class S>
  void mass_points(const S* x, S* g) const {
    const S phip = alpha0_ + x[2], phiq = alpha0_ + x[5];
    g[0] = x[0];
    g[1] = x[1];
    g[2] = l0_ * cos(phip);
    g[3] = l0_ * sin(phip);
    g[4] = x[3];
    g[5] = x[4];
    g[6] = l0_ * cos(phiq);
    g[7] = l0_ * sin(phiq);
  }
  const MassPoints<4, 2>& mass_model() const { return mass_; }

  // The mass matrix, convective inertia and gravity of the mass points written out (every
  // right-hand side needs them; the jets and the products with the 8 × 6 point Jacobian took four
  // to five times as long). The points are x_p, l0 t_p, x_q, l0 t_q, and a tangent turns with its β:
  // ∂(l0 t)/∂β = l0 n, n = (−sin φ, cos φ), and its convective acceleration is −l0 t β̇². With
  // W the 4 × 4 point mass matrix: M(node a, node b) = W(a, b) I for two positions, W(a, b) l0 n
  // between a position and a rotation, W(a, b) l0² n_a · n_b between two rotations;
  // h = Jgᵀ (W ⊗ I) γ and f = Jgᵀ (w ⊗ g) the same way.
  void mass(const double* x, const double* v, double* M, double* h) const override { inertia(x, v, nullptr, M, h, nullptr); }
  void mass_and_gravity(const double* x, const double* v, const double* g, double* M, double* h,
                        double* f) const override {
    inertia(x, v, g, M, h, f);
  }

  // σ1 = (EA/l0) e1, [σ2; σ3] = (EI/l0³) [[4, −2], [−2, 4]] [e2; e3]; with a shear stiffness
  // kGA (the third value, 0 or absent: shear-rigid) Timoshenko's bending pair (bending_pair).
  void constitutive(const std::vector<double>& v, double* S) const override {
    auto val = [&](size_t i) { return i < v.size() ? v[i] : 0.0; };
    for (int i = 0; i < 9; ++i) S[i] = 0.0;
    S[0] = val(0) / l0_;
    const BendingPair b = bending_pair(val(1), val(2), l0_);
    S[4] = S[8] = b.diagonal;
    S[5] = S[7] = b.coupling;
  }

 private:
  // δ / sin δ, the arc over the chord of a circular arc turning by 2δ (its series near 0, where
  // the quotient loses its digits).
  template <class S>
  static S arc_over_chord(const S& d) {
    if (std::abs(value_of(d)) < 1e-3) {
      const S d2 = d * d;
      return 1.0 + d2 / 6.0 + 7.0 * d2 * d2 / 360.0;
    }
    return d / sin(d);
  }

  // PLBEAMNL's second-order elongation from bending, (2 e2² + e2 e3 + 2 e3²) / (30 l0).
  template <class S>
  S bending_elongation(const S& e2, const S& e3) const {
    return (2.0 * e2 * e2 + e2 * e3 + 2.0 * e3 * e3) / (30.0 * l0_);
  }

  void inertia(const double* x, const double* v, const double* g, double* M, double* h, double* f) const {
    const auto& W = mass_.W;
    const double cp = std::cos(alpha0_ + x[2]), sp = std::sin(alpha0_ + x[2]);
    const double cq = std::cos(alpha0_ + x[5]), sq = std::sin(alpha0_ + x[5]);
    // Mass point a: its first coordinate column (x of a position, β of a tangent); the tangents
    // (a = 1, 3) turn, with ∂(l0 t)/∂β = l0 n.
    const int column[4] = {0, 2, 3, 5};
    const bool turns[4] = {false, true, false, true};
    const double tangent[4][2] = {{0, 0}, {-l0_ * sp, l0_ * cp}, {0, 0}, {-l0_ * sq, l0_ * cq}};
    for (int i = 0; i < 36; ++i) M[i] = 0.0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        const double w = W(a, b);
        const int ca = column[a], cb = column[b];
        if (!turns[a] && !turns[b]) {
          M[ca + 6 * cb] += w;
          M[ca + 1 + 6 * (cb + 1)] += w;
        } else if (!turns[a]) {
          M[ca + 6 * cb] += w * tangent[b][0];
          M[ca + 1 + 6 * cb] += w * tangent[b][1];
        } else if (!turns[b]) {
          M[ca + 6 * cb] += w * tangent[a][0];
          M[ca + 6 * (cb + 1)] += w * tangent[a][1];
        } else {
          M[ca + 6 * cb] += w * (tangent[a][0] * tangent[b][0] + tangent[a][1] * tangent[b][1]);
        }
      }
    // out += Jgᵀ (load (px, py) on point a): a position column takes the load itself, a rotation
    // column its product with l0 n.
    auto project = [&](int a, double px, double py, double* out) {
      if (turns[a]) {
        out[column[a]] += tangent[a][0] * px + tangent[a][1] * py;
      } else {
        out[column[a]] += px;
        out[column[a] + 1] += py;
      }
    };
    // γ of the tangents p and q, −l0 t β̇² (the positions have none); (W ⊗ I) γ per point.
    const double wp = v[2] * v[2], wq = v[5] * v[5];
    const double gp[2] = {-l0_ * cp * wp, -l0_ * sp * wp}, gq[2] = {-l0_ * cq * wq, -l0_ * sq * wq};
    for (int i = 0; i < 6; ++i) h[i] = 0.0;
    for (int a = 0; a < 4; ++a) project(a, W(a, 1) * gp[0] + W(a, 3) * gq[0], W(a, 1) * gp[1] + W(a, 3) * gq[1], h);
    if (!g) return;
    for (int i = 0; i < 6; ++i) f[i] = 0.0;
    for (int a = 0; a < 4; ++a) project(a, mass_.w[a] * g[0], mass_.w[a] * g[1], f);
  }

  double l0_, alpha0_;
  MassPoints<4, 2> mass_;
};

// LENGTHO and LGEOMY α0 (the chord angle) from the reference geometry x = (xp, yp, βp, xq, yq,
// βq), β at the reference 0.
void reference_plbeam(const double* x, const std::vector<double>&, double& l0, std::vector<double>& lgeomy) {
  l0 = std::hypot(x[3] - x[0], x[4] - x[1]);
  lgeomy = {std::atan2(x[4] - x[1], x[3] - x[0])};
}

template <Bending Kind>
ElementType plbeam_type() {
  const NodeKind p = NodeKind::XY, o = NodeKind::Beta;
  static const char* const name[] = {"PLBEAM", "PLBEAMNL", "PLBEAMC"};
  static const char* const first[] = {"elongation", "bending-corrected elongation", "elongation along the arc"};
  static const char* const title[] = {"planar beam", "planar beam with bending-corrected elongation",
                                      "planar beam exact for constant curvature: bending angles, elongation along the arc "
                                      "(extension)"};
  const int k = static_cast<int>(Kind);
  const bool arc = Kind == Bending::Arc;
  ElementType t = element_type<PlBeam<Kind>>(name[k], {p, o, p, o}, {"p1", "o1", "p2", "o2"},
                                             {first[k], arc ? "bending angle at p1" : "bending at p1",
                                              arc ? "bending angle at p2" : "bending at p2"},
                                             title[k]);
  set_stiffness(t, 3, "EA EI kGA");
  set_emass(t, 1, "rhoA");
  t.has_length = true;
  t.n_lgeomy = 1;
  t.reference = reference_plbeam;
  t.family = ElementFamily::Beam;
  t.extension = arc;
  return t;
}

}  // namespace

ElementType plbeam_element_type() { return plbeam_type<Bending::Sine>(); }
ElementType plbeamnl_element_type() { return plbeam_type<Bending::SineCorrected>(); }
ElementType plbeamc_element_type() { return plbeam_type<Bending::Arc>(); }

}  // namespace spacar
