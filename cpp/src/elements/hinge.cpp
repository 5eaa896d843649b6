// HINGE: relative rotation of two LAMBDA nodes about an axis (formulation.md §4.10).
// Hinge frame C0 = [e_x0 e_y0 e_z0] from the axis; e_j^{oi} = R(λ_oi) e_j0 and
// R̂_ab = e_a^{o1} · e_b^{o2}:
//   e1 = atan2((R̂32 − R̂23)/2, (R̂22 + R̂33)/2)   rotation of o2 relative to o1 about the axis
//   e2 = R̂13,  e3 = −R̂12                       misalignments, regular at every hinge angle
// e1 is an angle: the kinematic analysis unwraps it to a continuous multi-turn value.
#include <cmath>

#include "spacar/elements/registry.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"

namespace spacar {
namespace {

class Hinge : public AutoDiffElement<Hinge, 8, 3> {
 public:
  explicit Hinge(const ElementSetup& s) : C0_(frame(s.params)) {}

  template <class S>
  void deform(const S* x, S* e) const {
    const Vec3<S> x1 = rotate(x, C0_.col(0)), y1 = rotate(x, C0_.col(1)), z1 = rotate(x, C0_.col(2));
    const Vec3<S> y2 = rotate(x + 4, C0_.col(1)), z2 = rotate(x + 4, C0_.col(2));
    e[0] = atan2(0.5 * (dot3(z1, y2) - dot3(y1, z2)), 0.5 * (dot3(y1, y2) + dot3(z1, z2)));
    e[1] = dot3(x1, z2);
    e[2] = -dot3(x1, y2);
  }

  double period(int i) const override { return i == 0 ? 2.0 * M_PI : 0.0; }

  void constitutive(const std::vector<double>& v, double* S) const override {
    for (int i = 0; i < 9; ++i) S[i] = 0.0;
    S[0] = v.empty() ? 0.0 : v[0];
  }

 private:
  static Eigen::Matrix3d frame(const std::vector<double>& p) {
    if (p.size() != 3) throw InputError("HINGE: the axis needs 3 values, got " + std::to_string(p.size()));
    return hinge_frame(Eigen::Vector3d(p[0], p[1], p[2]), "HINGE");
  }

  Eigen::Matrix3d C0_;
};

}  // namespace

ElementType hinge_element_type() {
  ElementType t = element_type<Hinge>(
      "HINGE", {NodeKind::Lambda, NodeKind::Lambda}, {"o1", "o2"},
      {"rotation about the axis", "misalignment about local y", "misalignment about local z"}, "spatial hinge");
  set_params(t, 3, 3, "x y z: initial axis of rotation");
  set_stiffness(t, 1, "St (torsional stiffness of the rotation)");
  t.has_direction = true;
  t.family = ElementFamily::Hinge;
  return t;
}

}  // namespace spacar
