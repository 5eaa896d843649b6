// SURFACE: a point on a quadratic surface (formulation.md §4.12), absolute:
//   e1 = c1x² + c2y² + c3z² + c4xy + c5yz + c6zx + c7x + c8y + c9z + c10
// Fixed (e1 = 0) keeps the point on the surface; σ1 is the multiplier, the contact force on the
// point is −σ1 ∇f.
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class Surface : public AutoDiffElement<Surface, 3, 1> {
 public:
  explicit Surface(const ElementSetup& s) {
    if (s.params.size() != 10) throw InputError("SURFACE needs 10 coefficients");
    for (int i = 0; i < 10; ++i) c_[i] = s.params[i];
  }

  template <class S>
  void deform(const S* p, S* e) const {
    const S &x = p[0], &y = p[1], &z = p[2];
    e[0] = c_[0] * x * x + c_[1] * y * y + c_[2] * z * z + c_[3] * x * y + c_[4] * y * z + c_[5] * z * x +
           c_[6] * x + c_[7] * y + c_[8] * z + c_[9];
  }

 private:
  double c_[10];
};

}  // namespace

ElementType surface_element_type() {
  ElementType t = element_type<Surface>("SURFACE", {NodeKind::XYZ}, {"p1"}, {"surface function value"},
                                        "point on a quadratic surface");
  set_params(t, 10, 10, "c1..c10: coefficients of c1x²+c2y²+c3z²+c4xy+c5yz+c6zx+c7x+c8y+c9z+c10");
  return t;
}

}  // namespace spacar
