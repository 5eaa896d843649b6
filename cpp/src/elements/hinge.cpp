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

  // Written out, with the values of deform() (see BEAM): θ = atan2(N, D) with
  // N = (z1·y2 − y1·z2)/2, D = (y1·y2 + z1·z2)/2, ∂θ = (D ∂N − N ∂D)/(N² + D²).
  void first_derivatives(const double* x, double* e, double* B) const override {
    const Axes a = axes(x);
    Eigen::Map<Eigen::Matrix<double, 3, 8>> Bm(B);
    const double N = 0.5 * (a.z1.dot(a.y2) - a.y1.dot(a.z2)), D = 0.5 * (a.y1.dot(a.y2) + a.z1.dot(a.z2));
    const double r2 = N * N + D * D;
    e[0] = std::atan2(N, D);
    const Eigen::RowVector4d dN1 = 0.5 * (a.y2.transpose() * a.Jz1 - a.z2.transpose() * a.Jy1);
    const Eigen::RowVector4d dN2 = 0.5 * (a.z1.transpose() * a.Jy2 - a.y1.transpose() * a.Jz2);
    const Eigen::RowVector4d dD1 = 0.5 * (a.y2.transpose() * a.Jy1 + a.z2.transpose() * a.Jz1);
    const Eigen::RowVector4d dD2 = 0.5 * (a.y1.transpose() * a.Jy2 + a.z1.transpose() * a.Jz2);
    Bm.block<1, 4>(0, 0) = (D * dN1 - N * dD1) / r2;
    Bm.block<1, 4>(0, 4) = (D * dN2 - N * dD2) / r2;
    e[1] = a.x1.dot(a.z2);
    Bm.block<1, 4>(1, 0) = a.z2.transpose() * a.Jx1;
    Bm.block<1, 4>(1, 4) = a.x1.transpose() * a.Jz2;
    e[2] = -a.x1.dot(a.y2);
    Bm.block<1, 4>(2, 0) = -a.y2.transpose() * a.Jx1;
    Bm.block<1, 4>(2, 4) = -a.x1.transpose() * a.Jy2;
  }

  // c = d²e/dt² at ẍ = 0, with ẅ = 2 R(λ̇)c0 for an axis w = R(λ)c0 (see BEAM), and
  // θ̈ = (D N̈ − N D̈)/r² − 2 θ̇ (N Ṅ + D Ḋ)/r², θ̇ = (D Ṅ − N Ḋ)/r².
  void convective(const double* x, const double* v, double* c) const override {
    const Axes a = axes(x);
    const Eigen::Map<const Eigen::Vector4d> l1d(v), l2d(v + 4);
    const Eigen::Vector3d x1d = a.Jx1 * l1d, y1d = a.Jy1 * l1d, z1d = a.Jz1 * l1d, y2d = a.Jy2 * l2d,
                          z2d = a.Jz2 * l2d;
    const Eigen::Vector3d x1dd = 2.0 * rotated(v, C0_.col(0)), y1dd = 2.0 * rotated(v, C0_.col(1)),
                          z1dd = 2.0 * rotated(v, C0_.col(2)), y2dd = 2.0 * rotated(v + 4, C0_.col(1)),
                          z2dd = 2.0 * rotated(v + 4, C0_.col(2));
    const DotRates zy = dot_rates(a.z1, z1d, z1dd, a.y2, y2d, y2dd), yz = dot_rates(a.y1, y1d, y1dd, a.z2, z2d, z2dd);
    const DotRates yy = dot_rates(a.y1, y1d, y1dd, a.y2, y2d, y2dd), zz = dot_rates(a.z1, z1d, z1dd, a.z2, z2d, z2dd);
    const double N = 0.5 * (zy.value - yz.value), Nd = 0.5 * (zy.rate - yz.rate), Ndd = 0.5 * (zy.second - yz.second);
    const double D = 0.5 * (yy.value + zz.value), Dd = 0.5 * (yy.rate + zz.rate), Ddd = 0.5 * (yy.second + zz.second);
    const double r2 = N * N + D * D, thd = (D * Nd - N * Dd) / r2;
    c[0] = (D * Ndd - N * Ddd) / r2 - 2.0 * thd * (N * Nd + D * Dd) / r2;
    c[1] = dot_rates(a.x1, x1d, x1dd, a.z2, z2d, z2dd).second;
    c[2] = -dot_rates(a.x1, x1d, x1dd, a.y2, y2d, y2dd).second;
  }

  double period(int i) const override { return i == 0 ? 2.0 * M_PI : 0.0; }
  const Eigen::Matrix3d* axes_frame() const override { return &C0_; }

  void constitutive(const std::vector<double>& v, double* S) const override {
    for (int i = 0; i < 9; ++i) S[i] = 0.0;
    S[0] = v.empty() ? 0.0 : v[0];
  }

 private:
  using Mat34 = Eigen::Matrix<double, 3, 4>;
  // The hinge axes of o1 and the section axes y, z of o2, with their Jacobians.
  struct Axes {
    Eigen::Vector3d x1, y1, z1, y2, z2;
    Mat34 Jx1, Jy1, Jz1, Jy2, Jz2;
  };
  Axes axes(const double* x) const {
    return {rotated(x, C0_.col(0)),
            rotated(x, C0_.col(1)),
            rotated(x, C0_.col(2)),
            rotated(x + 4, C0_.col(1)),
            rotated(x + 4, C0_.col(2)),
            rotate_jacobian(x, C0_.col(0)),
            rotate_jacobian(x, C0_.col(1)),
            rotate_jacobian(x, C0_.col(2)),
            rotate_jacobian(x + 4, C0_.col(1)),
            rotate_jacobian(x + 4, C0_.col(2))};
  }

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
