// TRUSS: spatial truss between position nodes p and q; e1 = l − l0, σ1 = (EA/l0) e1, consistent
// mass of linear interpolation (formulation.md §4.1).
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class Truss : public AutoDiffElement<Truss, 6, 1, 2, 3> {
 public:
  explicit Truss(const ElementSetup& s) : l0_(s.l0) {
    const double rhoA = s.emass.empty() ? 0.0 : s.emass[0];
    mass_.W << 2.0, 1.0, 1.0, 2.0;
    mass_.W *= rhoA * l0_ / 6.0;
    mass_.w << 0.5 * rhoA * l0_, 0.5 * rhoA * l0_;
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const S dx = x[3] - x[0], dy = x[4] - x[1], dz = x[5] - x[2];
    e[0] = sqrt(dx * dx + dy * dy + dz * dz) - l0_;
  }

  template <class S>
  void mass_points(const S* x, S* g) const {
    for (int i = 0; i < 6; ++i) g[i] = x[i];
  }
  const MassPoints<2, 3>& mass_model() const { return mass_; }

  void constitutive(const std::vector<double>& v, double* S) const override {
    S[0] = v.empty() ? 0.0 : v[0] / l0_;
  }

 private:
  double l0_;
  MassPoints<2, 3> mass_;
};

}  // namespace

void reference_truss(const double* x, const std::vector<double>&, double& l0, std::vector<double>&) {
  l0 = reference_chord(x, x + 3, 3);
}

std::unique_ptr<ElementKernel> make_truss(const ElementSetup& s) { return std::make_unique<Truss>(s); }

}  // namespace spacar
