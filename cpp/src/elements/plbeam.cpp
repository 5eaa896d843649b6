// PLBEAM and PLBEAMNL: planar beam between p (x, y), its rotation βp, q (x, y) and βq.
// Formulation (verified against the manual's slider-crank, see docs/formulation.md):
//   φp = α0 + βp, φq = α0 + βq  material tangent angles (α0: reference chord angle, LGEOMY)
//   e1 = l − l0                                   elongation
//   e2 = −l0 (e_l · n_p) = l0 sin(φp − α)         bending at p (length units)
//   e3 = +l0 (e_l · n_q) = l0 sin(α − φq)         bending at q
// PLBEAMNL adds the bending correction (2e2² + e2e3 + 2e3²)/(30 l0) to e1: the excess of the
// arc length of the cubic deflection over the chord.
// Mass: consistent mass of the cubic Hermite interpolation with the nodal material tangents.
#include <cmath>

#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

template <bool Nonlinear>
class PlBeam : public AutoDiffElement<PlBeam<Nonlinear>, 6, 3, 4, 2> {
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
    // e_l · n(φ) = (−dx sin φ + dy cos φ) / l
    e[1] = -l0_ * (dy * cos(phip) - dx * sin(phip)) / l;
    e[2] = l0_ * (dy * cos(phiq) - dx * sin(phiq)) / l;
    e[0] = l - l0_;
    if constexpr (Nonlinear) e[0] += (2.0 * e[1] * e[1] + e[1] * e[2] + 2.0 * e[2] * e[2]) / (30.0 * l0_);
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

  // σ1 = (EA/l0) e1, [σ2; σ3] = (EI/l0³) [[4, −2], [−2, 4]] [e2; e3].
  void constitutive(const std::vector<double>& v, double* S) const override {
    const double EA = v.size() > 0 ? v[0] : 0.0, EI = v.size() > 1 ? v[1] : 0.0;
    const double k = EI / (l0_ * l0_ * l0_);
    for (int i = 0; i < 9; ++i) S[i] = 0.0;
    S[0] = EA / l0_;
    S[4] = 4.0 * k;
    S[5] = -2.0 * k;
    S[7] = -2.0 * k;
    S[8] = 4.0 * k;
  }

 private:
  double l0_, alpha0_;
  MassPoints<4, 2> mass_;
};

}  // namespace

void reference_plbeam(const double* x, const std::vector<double>&, double& l0, std::vector<double>& lgeomy) {
  // x = (xp, yp, βp, xq, yq, βq) with β at the reference 0.
  l0 = std::hypot(x[3] - x[0], x[4] - x[1]);
  lgeomy = {std::atan2(x[4] - x[1], x[3] - x[0])};
}

std::unique_ptr<ElementKernel> make_plbeam(const ElementSetup& s) { return std::make_unique<PlBeam<false>>(s); }
std::unique_ptr<ElementKernel> make_plbeamnl(const ElementSetup& s) { return std::make_unique<PlBeam<true>>(s); }

}  // namespace spacar
