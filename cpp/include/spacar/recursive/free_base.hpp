// A floating base's maps between its coordinates and its motion (spatial_tree.hpp's FreeBase;
// spatial_derivatives.cpp differentiates them).
#pragma once

#include "spacar/autodiff.hpp"

namespace spacar {

// A floating base's coordinates p = (x, μ) (its origin and three independent Euler parameters,
// the dependent one from the unit norm with its sign) and their rates, as functions on any scalar
// (double, or Jet for their exact derivatives: spatial_derivatives.cpp).
struct FreeBaseMaps {
  int dependent = 0;
  double sign = 1.0;

  // λ from μ; the dependent parameter 0 where |μ| ≥ 1 (no orientation: callers refuse it).
  template <class T>
  void lambda(const T* mu, T* l) const {
    T rest(1.0);
    for (int i = 0, k = 0; i < 4; ++i) {
      if (i == dependent) continue;
      l[i] = mu[k++];
      rest = rest - l[i] * l[i];
    }
    l[dependent] = value_of(rest) > 0.0 ? sign * sqrt(rest) : T(0.0);
  }
  template <class T>
  void lambda_rate(const T* l, const T* mud, T* ld) const {  // λ · λ̇ = 0
    T dot(0.0);
    for (int i = 0, k = 0; i < 4; ++i) {
      if (i == dependent) continue;
      ld[i] = mud[k++];
      dot = dot + l[i] * ld[i];
    }
    ld[dependent] = -dot / l[dependent];
  }
  template <class T>
  static void omega(const T* l, const T* ld, T* w) {  // ω = 2 E(λ) λ̇, world axes
    w[0] = 2.0 * (-l[1] * ld[0] + l[0] * ld[1] - l[3] * ld[2] + l[2] * ld[3]);
    w[1] = 2.0 * (-l[2] * ld[0] + l[3] * ld[1] + l[0] * ld[2] - l[1] * ld[3]);
    w[2] = 2.0 * (-l[3] * ld[0] - l[2] * ld[1] + l[1] * ld[2] + l[0] * ld[3]);
  }
  template <class T>
  static void e_transpose_times(const T* l, const T* w, T* out) {  // E(λ)ᵀ w
    out[0] = -(w[0] * l[1] + w[1] * l[2] + w[2] * l[3]);
    out[1] = l[0] * w[0] + w[1] * l[3] - w[2] * l[2];
    out[2] = l[0] * w[1] + w[2] * l[1] - w[0] * l[3];
    out[3] = l[0] * w[2] + w[0] * l[2] - w[1] * l[1];
  }
  template <class T>
  static void cross(const T* a, const T* b, T* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  }
  // ν = (ω; ẋ − ω × x): the base's twist at the world origin (also δ from δp).
  template <class T>
  void twist(const T* p, const T* pd, T* nu) const {
    T l[4], ld[4], xw[3];
    lambda(p + 3, l);
    lambda_rate(l, pd + 3, ld);
    omega(l, ld, nu);
    cross(nu, p, xw);
    for (int c = 0; c < 3; ++c) nu[3 + c] = pd[c] - xw[c];
  }
  // The wrench (n; f) at the world origin whose power on ν is that of the generalized forces
  // τ_p on ṗ: f = τ_x, n = x × f + A⁻ᵀ τ_μ with ω = A μ̇.
  template <class T>
  void wrench(const T* p, const T* tau, T* out) const {
    T l[4], A[3][3];
    lambda(p + 3, l);
    for (int m = 0; m < 3; ++m) {
      T e[3] = {T(0.0), T(0.0), T(0.0)}, ld[4], w[3];
      e[m] = T(1.0);
      lambda_rate(l, e, ld);
      omega(l, ld, w);
      for (int r = 0; r < 3; ++r) A[r][m] = w[r];
    }
    // Aᵀ y = τ_μ by Cramer's rule: y = adj(Aᵀ) τ_μ / det A, adj(Aᵀ) = cof(A).
    T cof[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        cof[r][c] = A[(r + 1) % 3][(c + 1) % 3] * A[(r + 2) % 3][(c + 2) % 3] -
                    A[(r + 1) % 3][(c + 2) % 3] * A[(r + 2) % 3][(c + 1) % 3];
    const T det = A[0][0] * cof[0][0] + A[0][1] * cof[0][1] + A[0][2] * cof[0][2];
    T xf[3];
    cross(p, tau, xf);
    for (int r = 0; r < 3; ++r) {
      out[r] = xf[r] + (cof[r][0] * tau[3] + cof[r][1] * tau[4] + cof[r][2] * tau[5]) / det;
      out[3 + r] = tau[r];
    }
  }
  // p̈ from ν̇ = (α; a_O): ẍ = a_O + α × x + ω × ẋ, λ̈ = ½ E(λ̇)ᵀ ω + ½ E(λ)ᵀ α.
  template <class T>
  void acceleration(const T* p, const T* pd, const T* nud, T* pdd) const {
    T l[4], ld[4], w[3], ax[3], wx[3], a[4], b[4];
    lambda(p + 3, l);
    lambda_rate(l, pd + 3, ld);
    omega(l, ld, w);
    cross(nud, p, ax);
    cross(w, pd, wx);
    for (int c = 0; c < 3; ++c) pdd[c] = nud[3 + c] + ax[c] + wx[c];
    e_transpose_times(ld, w, a);
    e_transpose_times(l, nud, b);
    for (int i = 0, k = 0; i < 4; ++i)
      if (i != dependent) pdd[3 + k++] = 0.5 * (a[i] + b[i]);
  }
};

}  // namespace spacar
