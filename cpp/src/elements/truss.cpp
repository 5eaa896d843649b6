// PLTRUSS and TRUSS: truss between the position nodes p and q, planar (DIM = 2) or spatial
// (DIM = 3); formulation.md §4.1.
//   e1 = l − l0 (elongation);  σ1 = (EA/l0) e1;  consistent mass of linear interpolation.
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

template <int DIM>
class Truss : public AutoDiffElement<Truss<DIM>, 2 * DIM, 1, 2, DIM> {
 public:
  explicit Truss(const ElementSetup& s)
      : l0_(s.l0), mass_(linear_mass<DIM>(s.emass.empty() ? 0.0 : s.emass[0], s.l0)) {}

  template <class S>
  void deform(const S* x, S* e) const {
    S l2 = S(0.0);
    for (int i = 0; i < DIM; ++i) l2 = l2 + (x[DIM + i] - x[i]) * (x[DIM + i] - x[i]);
    e[0] = sqrt(l2) - l0_;
  }

  template <class S>
  void mass_points(const S* x, S* g) const {
    for (int i = 0; i < 2 * DIM; ++i) g[i] = x[i];
  }
  const MassPoints<2, DIM>& mass_model() const { return mass_; }

  void constitutive(const std::vector<double>& v, double* S) const override {
    S[0] = v.empty() ? 0.0 : v[0] / l0_;
  }

 private:
  double l0_;
  MassPoints<2, DIM> mass_;
};

}  // namespace

void reference_pltruss(const double* x, const std::vector<double>&, double& l0, std::vector<double>&) {
  l0 = reference_chord(x, x + 2, 2);
}

void reference_truss(const double* x, const std::vector<double>&, double& l0, std::vector<double>&) {
  l0 = reference_chord(x, x + 3, 3);
}

std::unique_ptr<ElementKernel> make_pltruss(const ElementSetup& s) { return std::make_unique<Truss<2>>(s); }
std::unique_ptr<ElementKernel> make_truss(const ElementSetup& s) { return std::make_unique<Truss<3>>(s); }

}  // namespace spacar
