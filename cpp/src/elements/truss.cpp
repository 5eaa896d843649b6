// PLTRUSS and TRUSS: truss between the position nodes p1 and p2, planar (DIM = 2) or spatial
// (DIM = 3); formulation.md §4.1.
//   e1 = l − l0 (elongation);  σ1 = (EA/l0) e1;  consistent mass of linear interpolation.
#include <cmath>

#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

// The kernel: 2 DIM coordinates (p1, p2), 1 deformation, 2 mass points of dimension DIM.
template <int DIM>
class Truss : public AutoDiffElement<Truss<DIM>, 2 * DIM, 1, 2, DIM> {
 public:
  explicit Truss(const ElementSetup& s)
      : l0_(s.l0), mass_(linear_mass<DIM>(s.emass.empty() ? 0.0 : s.emass[0], s.l0)) {}

  // e = D(x), templated on the scalar: AutoDiffElement derives B, the convective term and the
  // stress-weighted Hessian from it.
  template <class S>
  void deform(const S* x, S* e) const {
    S l2 = S(0.0);
    for (int i = 0; i < DIM; ++i) l2 = l2 + (x[DIM + i] - x[i]) * (x[DIM + i] - x[i]);
    e[0] = sqrt(l2) - l0_;
  }

  // The points whose velocities carry the kinetic energy (the two nodes), with their weights.
  template <class S>
  void mass_points(const S* x, S* g) const {
    for (int i = 0; i < 2 * DIM; ++i) g[i] = x[i];
  }
  const MassPoints<2, DIM>& mass_model() const { return mass_; }

  // ESTIFF EA: σ1 = (EA/l0) e1.
  void constitutive(const std::vector<double>& v, double* S) const override {
    S[0] = v.empty() ? 0.0 : v[0] / l0_;
  }

 private:
  double l0_;
  MassPoints<2, DIM> mass_;
};

// LENGTHO from the reference positions x = (p1, p2): their distance.
template <int DIM>
void reference_length(const double* x, const std::vector<double>&, double& l0, std::vector<double>&) {
  double s = 0.0;
  for (int i = 0; i < DIM; ++i) s += (x[DIM + i] - x[i]) * (x[DIM + i] - x[i]);
  l0 = std::sqrt(s);
}

// The catalogue row shared by both: the node kind and the description differ.
template <int DIM>
ElementType truss_type(const char* name, NodeKind position, const char* description) {
  ElementType t = element_type<Truss<DIM>>(name, {position, position}, {"p1", "p2"}, {"elongation"}, description);
  set_stiffness(t, 1, "EA");
  set_emass(t, 1, "rhoA");
  t.has_length = true;
  t.reference = reference_length<DIM>;
  t.family = ElementFamily::Truss;
  return t;
}

}  // namespace

ElementType pltruss_element_type() { return truss_type<2>("PLTRUSS", NodeKind::XY, "planar truss"); }
ElementType truss_element_type() { return truss_type<3>("TRUSS", NodeKind::XYZ, "spatial truss"); }

}  // namespace spacar
