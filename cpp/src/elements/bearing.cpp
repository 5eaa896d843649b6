// BEARING: spatial bearing between p1 with its orientation o1 and p2 with o2 (formulation.md
// §4.11). With the hinge frame C0 of the axis (§4.10) and e_j^{o1} = R(λ_o1) C0 e_j:
//   e1..e3 = e_j^{o1} · (x_p2 − x_p1) − d0_j     axial and radial relative position in o1's frame
//   e4..e6 = HINGE deformations of (o1, o2)       rotation about the axis, two misalignments
// d0 (LGEOMY, 3 values) is the relative position at the reference.
#include <cmath>

#include "spacar/elements/registry.hpp"
#include "spacar/elements/spatial.hpp"

namespace spacar {
namespace {

class Bearing : public AutoDiffElement<Bearing, 14, 6> {
 public:
  explicit Bearing(const ElementSetup& s) {
    if (s.params.size() != 3 || s.lgeomy.size() != 3)
      throw InputError("BEARING needs its axis (3 values) and 3 reference values (LGEOMY)");
    C0_ = hinge_frame(Eigen::Vector3d(s.params[0], s.params[1], s.params[2]), "BEARING");
    d0_ = Eigen::Vector3d(s.lgeomy[0], s.lgeomy[1], s.lgeomy[2]);
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const S* l1 = x + 3;
    const S* l2 = x + 10;
    const Vec3<S> d = {x[7] - x[0], x[8] - x[1], x[9] - x[2]};
    const Vec3<S> x1 = rotate(l1, C0_.col(0)), y1 = rotate(l1, C0_.col(1)), z1 = rotate(l1, C0_.col(2));
    const Vec3<S> y2 = rotate(l2, C0_.col(1)), z2 = rotate(l2, C0_.col(2));
    e[0] = dot3(x1, d) - d0_[0];
    e[1] = dot3(y1, d) - d0_[1];
    e[2] = dot3(z1, d) - d0_[2];
    e[3] = atan2(0.5 * (dot3(z1, y2) - dot3(y1, z2)), 0.5 * (dot3(y1, y2) + dot3(z1, z2)));
    e[4] = dot3(x1, z2);
    e[5] = -dot3(x1, y2);
  }

  double period(int i) const override { return i == 3 ? 2.0 * M_PI : 0.0; }

 private:
  Eigen::Matrix3d C0_;
  Eigen::Vector3d d0_;
};

void reference_bearing(const double* x, const std::vector<double>& params, double&, std::vector<double>& lgeomy) {
  const Eigen::Matrix3d C0 = hinge_frame(Eigen::Vector3d(params[0], params[1], params[2]), "");
  const Eigen::Vector3d d = C0.transpose() * Eigen::Vector3d(x[7] - x[0], x[8] - x[1], x[9] - x[2]);
  lgeomy = {d[0], d[1], d[2]};
}

}  // namespace

ElementType bearing_element_type() {
  const NodeKind p = NodeKind::XYZ, o = NodeKind::Lambda;
  ElementType t = element_type<Bearing>("BEARING", {p, o, p, o}, {"p1", "o1", "p2", "o2"},
                                        {"axial displacement", "radial displacement along local y",
                                         "radial displacement along local z", "rotation about the axis",
                                         "misalignment about local y", "misalignment about local z"},
                                        "spatial bearing");
  set_params(t, 3, 3, "x y z: initial axis of rotation");
  t.n_lgeomy = 3;
  t.has_direction = true;
  t.reference = reference_bearing;
  t.family = ElementFamily::Bearing;
  return t;
}

}  // namespace spacar
