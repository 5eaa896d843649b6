// WHEEL (extension): a thin disc rolling without slip on a plane n·x = 0 (formulation.md §4.14).
// p1: wheel centre, o1: wheel body. Axle a = R(λ) â0, s = √(1 − (n·a)²), t1 = (a × n)/s
// (longitudinal), t2 = n × t1 (lateral), ω = 2 E(λ) λ̇ (global angular velocity):
//   e1 = n · x_p1 − r s                  height of the lowest rim point (holonomic; fixed: contact)
//   ė2 = t1 · ẋ_p1 − r a · ω             longitudinal slip (velocity level)
//   ė3 = t2 · ẋ_p1 + r s t1 · ω          lateral slip (velocity level)
// Knife-edge rolling: e1 fixed, e2 and e3 ENHC.
#include <cmath>

#include "spacar/elements/registry.hpp"
#include "spacar/elements/spatial.hpp"

namespace spacar {
namespace {

class Wheel : public AutoDiffElement<Wheel, 7, 3> {
 public:
  static constexpr unsigned kVelocityRows = 0b110;

  explicit Wheel(const ElementSetup& s) {
    const auto& p = s.params;
    if (p.size() != 4 && p.size() != 7) throw InputError("WHEEL needs ax ay az r [nx ny nz]");
    a0_ = Eigen::Vector3d(p[0], p[1], p[2]);
    r_ = p[3];
    n_ = p.size() == 7 ? Eigen::Vector3d(p[4], p[5], p[6]) : Eigen::Vector3d(0, 0, 1);
    if (!(a0_.norm() > 0.0)) throw InputError("WHEEL: the axle direction has zero length");
    if (!(n_.norm() > 0.0)) throw InputError("WHEEL: the ground-plane normal has zero length");
    if (!(r_ > 0.0)) throw InputError("WHEEL: the radius must be positive");
    a0_.normalize();
    n_.normalize();
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const Vec3<S> a = rotate(x + 3, a0_);
    const S na = n_[0] * a[0] + n_[1] * a[1] + n_[2] * a[2];
    e[0] = n_[0] * x[0] + n_[1] * x[1] + n_[2] * x[2] - r_ * sqrt(1.0 - na * na);
    e[1] = S(0.0);
    e[2] = S(0.0);
  }

  template <class S>
  void slip_rates(const S* x, const S* v, S* edot) const {
    const S* l = x + 3;
    const S* ld = v + 3;
    const Vec3<S> a = rotate(l, a0_);
    const S na = n_[0] * a[0] + n_[1] * a[1] + n_[2] * a[2];
    const S s = sqrt(1.0 - na * na);
    const Vec3<S> t1 = {(a[1] * n_[2] - a[2] * n_[1]) / s, (a[2] * n_[0] - a[0] * n_[2]) / s,
                        (a[0] * n_[1] - a[1] * n_[0]) / s};
    const Vec3<S> t2 = {n_[1] * t1[2] - n_[2] * t1[1], n_[2] * t1[0] - n_[0] * t1[2], n_[0] * t1[1] - n_[1] * t1[0]};
    // ω = 2 E(λ) λ̇
    const Vec3<S> w = {2.0 * (-l[1] * ld[0] + l[0] * ld[1] - l[3] * ld[2] + l[2] * ld[3]),
                       2.0 * (-l[2] * ld[0] + l[3] * ld[1] + l[0] * ld[2] - l[1] * ld[3]),
                       2.0 * (-l[3] * ld[0] - l[2] * ld[1] + l[1] * ld[2] + l[0] * ld[3])};
    const Vec3<S> xd = {v[0], v[1], v[2]};
    edot[0] = S(0.0);
    edot[1] = dot3(t1, xd) - r_ * dot3(a, w);
    edot[2] = dot3(t2, xd) + r_ * s * dot3(t1, w);
  }

 private:
  Eigen::Vector3d a0_, n_;
  double r_;
};

}  // namespace

std::unique_ptr<ElementKernel> make_wheel(const ElementSetup& s) { return std::make_unique<Wheel>(s); }

}  // namespace spacar
