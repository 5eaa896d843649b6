// Forward-mode dual numbers ("jets") used to derive exact first and second derivatives of the
// element deformation functions, which are written once as templates on the scalar type.
// Jet<T, N> carries a value and N directional derivatives; nesting Jet<Jet<double, 1>, 1>
// gives second directional derivatives (the convective terms of SPACAR).
#pragma once

#include <array>
#include <cmath>

namespace spacar {

template <class T, int N>
struct Jet {
  T a{};
  std::array<T, N> d{};

  Jet() = default;
  Jet(double value) : a(value) {}  // NOLINT: implicit from constants, as a scalar would be
  Jet(const T& value, const std::array<T, N>& derivs) : a(value), d(derivs) {}

  // A variable: value v with unit derivative in direction k.
  static Jet variable(const T& v, int k) {
    Jet j(v, {});
    j.d[k] = T(1.0);
    return j;
  }

  Jet& operator+=(const Jet& o) { return *this = *this + o; }
  Jet& operator-=(const Jet& o) { return *this = *this - o; }
  Jet& operator*=(const Jet& o) { return *this = *this * o; }
  Jet& operator/=(const Jet& o) { return *this = *this / o; }
};

// Value of any scalar (double or nested jet), for branch decisions.
inline double value_of(double x) { return x; }
template <class T, int N>
double value_of(const Jet<T, N>& x) { return value_of(x.a); }

template <class T, int N>
Jet<T, N> operator+(const Jet<T, N>& x, const Jet<T, N>& y) {
  Jet<T, N> r(x.a + y.a, {});
  for (int k = 0; k < N; ++k) r.d[k] = x.d[k] + y.d[k];
  return r;
}
template <class T, int N>
Jet<T, N> operator-(const Jet<T, N>& x, const Jet<T, N>& y) {
  Jet<T, N> r(x.a - y.a, {});
  for (int k = 0; k < N; ++k) r.d[k] = x.d[k] - y.d[k];
  return r;
}
template <class T, int N>
Jet<T, N> operator-(const Jet<T, N>& x) {
  Jet<T, N> r(-x.a, {});
  for (int k = 0; k < N; ++k) r.d[k] = -x.d[k];
  return r;
}
template <class T, int N>
Jet<T, N> operator*(const Jet<T, N>& x, const Jet<T, N>& y) {
  Jet<T, N> r(x.a * y.a, {});
  for (int k = 0; k < N; ++k) r.d[k] = x.d[k] * y.a + x.a * y.d[k];
  return r;
}
template <class T, int N>
Jet<T, N> operator/(const Jet<T, N>& x, const Jet<T, N>& y) {
  const T inv = T(1.0) / y.a;
  const T q = x.a * inv;
  Jet<T, N> r(q, {});
  for (int k = 0; k < N; ++k) r.d[k] = (x.d[k] - q * y.d[k]) * inv;
  return r;
}
// Mixed operations with plain doubles.
template <class T, int N>
Jet<T, N> operator+(const Jet<T, N>& x, double y) { return x + Jet<T, N>(y); }
template <class T, int N>
Jet<T, N> operator+(double x, const Jet<T, N>& y) { return Jet<T, N>(x) + y; }
template <class T, int N>
Jet<T, N> operator-(const Jet<T, N>& x, double y) { return x - Jet<T, N>(y); }
template <class T, int N>
Jet<T, N> operator-(double x, const Jet<T, N>& y) { return Jet<T, N>(x) - y; }
template <class T, int N>
Jet<T, N> operator*(const Jet<T, N>& x, double y) {
  Jet<T, N> r(x.a * y, {});
  for (int k = 0; k < N; ++k) r.d[k] = x.d[k] * y;
  return r;
}
template <class T, int N>
Jet<T, N> operator*(double x, const Jet<T, N>& y) { return y * x; }
template <class T, int N>
Jet<T, N> operator/(const Jet<T, N>& x, double y) { return x * (1.0 / y); }
template <class T, int N>
Jet<T, N> operator/(double x, const Jet<T, N>& y) { return Jet<T, N>(x) / y; }

// Chain rule: f(x) with f'(x) = df.
template <class T, int N>
Jet<T, N> chain(const Jet<T, N>& x, const T& f, const T& df) {
  Jet<T, N> r(f, {});
  for (int k = 0; k < N; ++k) r.d[k] = df * x.d[k];
  return r;
}

using std::asin;
using std::atan2;
using std::cos;
using std::sin;
using std::sqrt;

template <class T, int N>
Jet<T, N> sin(const Jet<T, N>& x) { return chain(x, T(sin(x.a)), T(cos(x.a))); }
template <class T, int N>
Jet<T, N> cos(const Jet<T, N>& x) { return chain(x, T(cos(x.a)), T(-sin(x.a))); }
template <class T, int N>
Jet<T, N> sqrt(const Jet<T, N>& x) {
  const T s = sqrt(x.a);
  return chain(x, s, T(0.5 / s));
}
template <class T, int N>
Jet<T, N> asin(const Jet<T, N>& x) { return chain(x, T(asin(x.a)), T(1.0 / sqrt(1.0 - x.a * x.a))); }
template <class T, int N>
Jet<T, N> atan2(const Jet<T, N>& y, const Jet<T, N>& x) {
  const T r2 = x.a * x.a + y.a * y.a;
  Jet<T, N> r(atan2(y.a, x.a), {});
  for (int k = 0; k < N; ++k) r.d[k] = (x.a * y.d[k] - y.a * x.d[k]) / r2;
  return r;
}

}  // namespace spacar
