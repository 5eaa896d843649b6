// PLTRUSS: planar truss between position nodes p (x1, x2) and q (x3, x4).
//   e1 = l − l0 (elongation);  σ1 = (EA/l0) e1;  consistent mass of linear interpolation.
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class PlTruss : public AutoDiffElement<PlTruss, 4, 1, 2, 2> {
 public:
  explicit PlTruss(const ElementSetup& s) : l0_(s.l0) {
    const double rhoA = s.emass.empty() ? 0.0 : s.emass[0];
    mass_.W << 2.0, 1.0, 1.0, 2.0;
    mass_.W *= rhoA * l0_ / 6.0;
    mass_.w << 0.5 * rhoA * l0_, 0.5 * rhoA * l0_;
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const S dx = x[2] - x[0], dy = x[3] - x[1];
    e[0] = sqrt(dx * dx + dy * dy) - l0_;
  }

  template <class S>
  void mass_points(const S* x, S* g) const {
    for (int i = 0; i < 4; ++i) g[i] = x[i];
  }
  const MassPoints<2, 2>& mass_model() const { return mass_; }

  void constitutive(const std::vector<double>& v, double* S) const override {
    S[0] = v.empty() ? 0.0 : v[0] / l0_;
  }

 private:
  double l0_;
  MassPoints<2, 2> mass_;
};

}  // namespace

void reference_pltruss(const double* x, const std::vector<double>&, double& l0, std::vector<double>&) {
  l0 = reference_chord(x, x + 2, 2);
}

std::unique_ptr<ElementKernel> make_pltruss(const ElementSetup& s) { return std::make_unique<PlTruss>(s); }

}  // namespace spacar
