// PLWHEEL: a wheel rolling on the plane of the model, seen from above (formulation.md §4.7).
// p1: wheel centre / contact point, o1: heading of the axle, o2: spin about the axle.
// Axle a = R(β_o1) â0 (â0 the normalised axis x y of the definition line), rolling direction
// t = (a_y, −a_x). Both deformations are velocity-level (slips):
//   ė1 = t · ẋ_p1 − r β̇_o2      longitudinal slip
//   ė2 = a · ẋ_p1               lateral slip
// ENHC both for rolling without slip; RLSE with EDAMPP d1 d2 for a linear creep model.
#include <cmath>

#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class PlWheel : public AutoDiffElement<PlWheel, 4, 2> {
 public:
  static constexpr unsigned kVelocityRows = 0b11;

  explicit PlWheel(const ElementSetup& s) {
    if (s.params.size() != 3) throw InputError("PLWHEEL needs r x y");
    r_ = s.params[0];
    const double n = std::hypot(s.params[1], s.params[2]);
    if (!(r_ > 0.0)) throw InputError("PLWHEEL: the radius must be positive");
    if (!(n > 0.0)) throw InputError("PLWHEEL: the axis of rotation has zero length");
    a0_[0] = s.params[1] / n;
    a0_[1] = s.params[2] / n;
  }

  template <class S>
  void deform(const S*, S* e) const {
    e[0] = S(0.0);
    e[1] = S(0.0);
  }

  template <class S>
  void slip_rates(const S* x, const S* v, S* edot) const {
    const S c = cos(x[2]), s = sin(x[2]);
    const S ax = c * a0_[0] - s * a0_[1], ay = s * a0_[0] + c * a0_[1];
    edot[0] = ay * v[0] - ax * v[1] - r_ * v[3];
    edot[1] = ax * v[0] + ay * v[1];
  }

  // EDAMPP d1 d2: σ = diag(d1, d2) ė (creep damping of released slips).
  void constitutive(const std::vector<double>& v, double* S) const override {
    S[0] = v.size() > 0 ? v[0] : 0.0;
    S[1] = S[2] = 0.0;
    S[3] = v.size() > 1 ? v[1] : 0.0;
  }

 private:
  double r_;
  double a0_[2];
};

}  // namespace

ElementType plwheel_element_type() {
  ElementType t = element_type<PlWheel>("PLWHEEL", {NodeKind::XY, NodeKind::Beta, NodeKind::Beta},
                                        {"p1", "o1", "o2"}, {"longitudinal slip", "lateral slip"}, "planar wheel");
  set_params(t, 3, 3, "r x y: radius and initial axis of rotation");
  t.edampp = "d1 d2: linear creep damping of the released slips (extension)";
  t.n_estiff = 2;
  t.family = ElementFamily::Wheel;
  return t;
}

}  // namespace spacar
