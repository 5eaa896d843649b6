// Helpers for spatial elements, templated on the scalar type: rotation of a vector by Euler
// parameters, R(λ)c = (λ0² − λ̄·λ̄) c + 2 λ̄ (λ̄·c) + 2 λ0 λ̄ × c (formulation.md §0). The
// quadratic form is used also off the unit sphere, where Newton iterates go; all derivatives are
// exact derivatives of this form.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <string>

namespace spacar {

template <class S>
using Vec3 = std::array<S, 3>;

template <class S>
S dot3(const Vec3<S>& a, const Vec3<S>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// R(λ) c for a constant vector c; l points to (λ0, λ1, λ2, λ3).
template <class S>
Vec3<S> rotate(const S* l, const Eigen::Vector3d& c) {
  const S s = l[0] * l[0] - (l[1] * l[1] + l[2] * l[2] + l[3] * l[3]);
  const S lc = l[1] * c[0] + l[2] * c[1] + l[3] * c[2];
  // λ̄ × c
  const S cx = l[2] * c[2] - l[3] * c[1];
  const S cy = l[3] * c[0] - l[1] * c[2];
  const S cz = l[1] * c[1] - l[2] * c[0];
  return {s * c[0] + 2.0 * l[1] * lc + 2.0 * l[0] * cx, s * c[1] + 2.0 * l[2] * lc + 2.0 * l[0] * cy,
          s * c[2] + 2.0 * l[3] * lc + 2.0 * l[0] * cz};
}

// R(λ) c as an Eigen vector, and its Jacobian ∂(R(λ)c)/∂λ (3×4) — exact for the quadratic form.
// Along a motion (λ̈ = 0) the second rate of R(λ)c is 2 R(λ̇)c, the form at λ̇: the written-out
// convective terms of the spatial elements use that.
inline Eigen::Vector3d rotated(const double* l, const Eigen::Vector3d& c) {
  const Vec3<double> r = rotate(l, c);
  return {r[0], r[1], r[2]};
}
Eigen::Matrix<double, 3, 4> rotate_jacobian(const double* l, const Eigen::Vector3d& c);

// The cross-product matrix: skew(v) w = v × w.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

// u·w with its first and second rates, from those of u and w (the written-out convective terms).
struct DotRates {
  double value, rate, second;
};
inline DotRates dot_rates(const Eigen::Vector3d& u, const Eigen::Vector3d& ud, const Eigen::Vector3d& udd,
                          const Eigen::Vector3d& w, const Eigen::Vector3d& wd, const Eigen::Vector3d& wdd) {
  return {u.dot(w), ud.dot(w) + u.dot(wd), udd.dot(w) + 2.0 * ud.dot(wd) + u.dot(wdd)};
}

// Orthonormal frame [e_x e_y e_z] with e_x along `axis` and e_y from `y_hint` (its e_x component
// removed). Throws InputError (message names `what`) if the axis has zero length or the hint is
// parallel to the axis (remainder below 1e-5 of its length).
Eigen::Matrix3d frame_from_axis(const Eigen::Vector3d& axis, const Eigen::Vector3d& y_hint, const std::string& what);

// The hinge frame (formulation.md §4.10): e_x the axis, e_y the global unit axis along which
// the axis has its smallest component, orthogonalised.
Eigen::Matrix3d hinge_frame(const Eigen::Vector3d& axis, const std::string& what);

// G(λ): ω' = 2 G(λ) λ̇ is the body-frame angular velocity (formulation.md §0).
Eigen::Matrix<double, 3, 4> euler_G(const double* l);
// E(λ): ω = 2 E(λ) λ̇ is the angular velocity in global axes (formulation.md §0).
Eigen::Matrix<double, 3, 4> euler_E(const Eigen::Vector4d& l);
// R(λ) = E(λ) G(λ)ᵀ: body axes → global.
Eigen::Matrix3d euler_R(const Eigen::Vector4d& l);

// Mass and convective inertia force of rotational kinetic energy
// T = ½ Σ_ij ω_iᵀ A_ij ω_j with ω_i = 2 G(λ_i) λ̇_i the body angular velocity of LAMBDA block i
// (coordinates lam[i]..lam[i]+3 of x and v). Adds 4 G_iᵀ A_ij G_j to M (n x n, column-major)
// and 4 G(λ̇_i)ᵀ Σ_j A_ij ω_j to h. This is the exact Lagrange form (formulation.md §3.2).
void add_rotational_inertia(int n, const double* x, const double* v, const int* lam, int nblocks,
                            const Eigen::Matrix3d* A, double* M, double* h);

}  // namespace spacar
