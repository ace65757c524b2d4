// Forward-mode dual numbers with a fixed number of directions.
//
// The variational equations of the shooting method are the directional derivatives of the
// rod equations along the columns of the state-transition matrix. Evaluating the right-hand
// side once on Dual<N> with those columns as seeds gives J(y) * Phi exactly (no truncation
// error), which is what makes the shooting Jacobian exact to the integrator's tolerance.
#pragma once

#include <array>
#include <cmath>

namespace kirchhoff {

template <int N>
struct Dual {
  double v = 0.0;                   // value
  std::array<double, N> d{};        // derivatives along the N seed directions

  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants promote implicitly, as in real arithmetic

  Dual& operator+=(const Dual& o) { v += o.v; for (int i = 0; i < N; ++i) d[i] += o.d[i]; return *this; }
  Dual& operator-=(const Dual& o) { v -= o.v; for (int i = 0; i < N; ++i) d[i] -= o.d[i]; return *this; }
  Dual& operator*=(const Dual& o) {
    for (int i = 0; i < N; ++i) d[i] = d[i] * o.v + v * o.d[i];
    v *= o.v;
    return *this;
  }
  Dual& operator/=(const Dual& o) {
    const double inv = 1.0 / o.v;
    for (int i = 0; i < N; ++i) d[i] = (d[i] - v * inv * o.d[i]) * inv;
    v *= inv;
    return *this;
  }
  Dual& operator*=(double c) { v *= c; for (int i = 0; i < N; ++i) d[i] *= c; return *this; }
};

template <int N> Dual<N> operator+(Dual<N> a, const Dual<N>& b) { return a += b; }
template <int N> Dual<N> operator-(Dual<N> a, const Dual<N>& b) { return a -= b; }
template <int N> Dual<N> operator*(Dual<N> a, const Dual<N>& b) { return a *= b; }
template <int N> Dual<N> operator/(Dual<N> a, const Dual<N>& b) { return a /= b; }
template <int N> Dual<N> operator*(Dual<N> a, double c) { return a *= c; }
template <int N> Dual<N> operator*(double c, Dual<N> a) { return a *= c; }
template <int N> Dual<N> operator+(Dual<N> a, double c) { a.v += c; return a; }
template <int N> Dual<N> operator+(double c, Dual<N> a) { a.v += c; return a; }
template <int N> Dual<N> operator-(Dual<N> a, double c) { a.v -= c; return a; }
template <int N> Dual<N> operator-(double c, const Dual<N>& a) { Dual<N> r = -a; r.v += c; return r; }
template <int N> Dual<N> operator/(Dual<N> a, double c) { return a *= (1.0 / c); }
template <int N> Dual<N> operator/(double c, const Dual<N>& a) { return Dual<N>(c) / a; }
template <int N> Dual<N> operator-(const Dual<N>& a) { Dual<N> r = a; r *= -1.0; return r; }

template <int N> Dual<N> sqrt(const Dual<N>& a) {
  Dual<N> r;
  r.v = std::sqrt(a.v);
  const double k = 0.5 / r.v;
  for (int i = 0; i < N; ++i) r.d[i] = k * a.d[i];
  return r;
}
template <int N> Dual<N> sin(const Dual<N>& a) {
  Dual<N> r;
  r.v = std::sin(a.v);
  const double c = std::cos(a.v);
  for (int i = 0; i < N; ++i) r.d[i] = c * a.d[i];
  return r;
}
template <int N> Dual<N> cos(const Dual<N>& a) {
  Dual<N> r;
  r.v = std::cos(a.v);
  const double s = -std::sin(a.v);
  for (int i = 0; i < N; ++i) r.d[i] = s * a.d[i];
  return r;
}

template <int N> Dual<N> asin(const Dual<N>& a) {
  Dual<N> r;
  r.v = std::asin(a.v);
  const double k = 1.0 / std::sqrt(1.0 - a.v * a.v);
  for (int i = 0; i < N; ++i) r.d[i] = k * a.d[i];
  return r;
}
template <int N> Dual<N> atan2(const Dual<N>& y, const Dual<N>& x) {
  Dual<N> r;
  r.v = std::atan2(y.v, x.v);
  const double inv = 1.0 / (x.v * x.v + y.v * y.v);
  for (int i = 0; i < N; ++i) r.d[i] = (x.v * y.d[i] - y.v * x.d[i]) * inv;
  return r;
}

inline double value(double x) { return x; }
template <int N> double value(const Dual<N>& x) { return x.v; }

}  // namespace kirchhoff
