// Internal: the formulas of rod_on_cylinder.hpp on any scalar type of the right-hand sides (double
// for the state, Dual<K> for the variational equations), for the spatial state layout.
#pragma once

#include <cmath>

#include "kirchhoff/equations/detail/dual.hpp"
#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"
#include "kirchhoff/equations/detail/spatial_state.hpp"

namespace kirchhoff::detail {

// CylinderSupport::rate when none is given, times the radius.
constexpr double kDefaultSupportRate = 0.1;

// A value and its derivative along the unloaded rod equations: one forward-mode direction on top
// of whatever T carries, so that D g''' comes out of evaluating g''' once.
template <class T>
struct Jet {
  T v{}, d{};
  Jet() = default;
  Jet(double c) : v(c), d(0.0) {}  // NOLINT: constants promote, as in real arithmetic
  Jet(T value, T derivative) : v(value), d(derivative) {}
};
template <class T> Jet<T> operator+(const Jet<T>& a, const Jet<T>& b) { return {a.v + b.v, a.d + b.d}; }
template <class T> Jet<T> operator-(const Jet<T>& a, const Jet<T>& b) { return {a.v - b.v, a.d - b.d}; }
template <class T> Jet<T> operator-(const Jet<T>& a) { return {-a.v, -a.d}; }
template <class T> Jet<T> operator*(const Jet<T>& a, const Jet<T>& b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
template <class T> Jet<T> operator/(const Jet<T>& a, const Jet<T>& b) {
  const T inv = 1.0 / b.v;
  const T q = a.v * inv;
  return {q, (a.d - q * b.d) * inv};
}
template <class T> Jet<T> operator*(double c, const Jet<T>& a) { return {c * a.v, c * a.d}; }
template <class T> Jet<T> operator+(double c, const Jet<T>& a) { return {c + a.v, a.d}; }
template <class T> Jet<T> operator-(double c, const Jet<T>& a) { return {c - a.v, -a.d}; }
template <class T> Jet<T> operator-(const Jet<T>& a, double c) { return {a.v - c, a.d}; }
template <class T> Jet<T> operator*(const Jet<T>& a, double c) { return {a.v * c, a.d * c}; }
template <class T> Jet<T> operator/(double c, const Jet<T>& a) {
  const T q = c / a.v;
  return {q, -(q / a.v) * a.d};
}
template <class T> Jet<T> sqrt(const Jet<T>& a) {
  using std::sqrt;
  const T r = sqrt(a.v);
  return {r, a.d * (0.5 / r)};
}

// Just enough 3-vector arithmetic for the formulas, on any scalar.
template <class S>
struct V3 {
  S c[3];
  const S& operator[](int i) const { return c[i]; }
};
template <class S> S dot(const V3<S>& a, const V3<S>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
template <class S> S dot(const Vec3& a, const V3<S>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
template <class S> V3<S> cross(const V3<S>& a, const V3<S>& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}
template <class S> V3<S> operator-(const V3<S>& a, const V3<S>& b) { return {{a[0] - b[0], a[1] - b[1], a[2] - b[2]}}; }
template <class S> V3<S> scaled(const V3<S>& a, const S& k) { return {{a[0] * k, a[1] * k, a[2] * k}}; }
template <class S> V3<S> scaled(const Vec3& a, const S& k) { return {{a[0] * k, a[1] * k, a[2] * k}}; }

// g = rho - radius and g', g'', g''' (rod_on_cylinder.hpp), with the outward unit vector e.
template <class S>
struct CylinderGaps {
  S g[4];
  V3<S> e;
};
template <class S>
CylinderGaps<S> cylinder_gaps(const CylinderSupport& c, double B, const V3<S>& r, const V3<S>& t, const V3<S>& m,
                              const V3<S>& n) {
  using std::sqrt;
  const Vec3& a = c.axis;
  const V3<S> d{{r[0] - c.point[0], r[1] - c.point[1], r[2] - c.point[2]}};
  const V3<S> w = d - scaled(a, dot(a, d));
  const S rho = sqrt(dot(w, w));
  const S inv_rho = 1.0 / rho;
  CylinderGaps<S> out;
  out.e = scaled(w, inv_rho);
  const V3<S>& e = out.e;
  const V3<S> k = scaled(cross(m, t), S(1.0 / B));
  const S alpha = dot(a, t), t_rho = dot(e, t), ek = dot(e, k), ak = dot(a, k);
  const S X = 1.0 - (alpha * alpha + t_rho * t_rho);
  out.g[0] = rho - c.radius;
  out.g[1] = t_rho;
  out.g[2] = X * inv_rho + ek;
  out.g[3] = -(3.0 * (alpha * ak) + 2.0 * (t_rho * out.g[2]) + t_rho * ek) * inv_rho - X * t_rho * inv_rho * inv_rho +
             (dot(n, t) * t_rho - dot(e, n) + dot(e, cross(m, k))) * (1.0 / B);
  return out;
}

// The frame's d3 and the vectors r, m, n of a spatial state.
template <class T>
void spatial_vectors(const T* y, V3<T>* r, V3<T>* t, V3<T>* m, V3<T>* n) {
  T R[3][3];
  rotation_from_quaternion(y + kQ, R);
  *r = {{y[kR], y[kR + 1], y[kR + 2]}};
  *t = {{R[0][2], R[1][2], R[2][2]}};
  *m = {{y[kM], y[kM + 1], y[kM + 2]}};
  *n = {{y[kN], y[kN + 1], y[kN + 2]}};
}

// The cylinder's pressure p at the spatial state y and the direction e it acts along: g'''' plus
// the Baumgarte terms vanish (rod_on_cylinder.hpp). D g''' comes from g''' on jets whose
// derivatives are those of the unloaded equations: r' = t, t' = (m x t)/B, m' = n x t, n' = 0.
template <class T>
T cylinder_pressure(const CylinderSupport& c, double B, const T* y, V3<T>* direction) {
  V3<T> r, t, m, n;
  spatial_vectors(y, &r, &t, &m, &n);
  const V3<T> k = scaled(cross(m, t), T(1.0 / B)), dm = cross(n, t);
  auto jet = [](const V3<T>& v, const V3<T>& dv) {
    return V3<Jet<T>>{{{v[0], dv[0]}, {v[1], dv[1]}, {v[2], dv[2]}}};
  };
  const V3<T> zero{{T(0.0), T(0.0), T(0.0)}};
  const CylinderGaps<Jet<T>> G = cylinder_gaps(c, B, jet(r, t), jet(t, k), jet(m, dm), jet(n, zero));
  const double w = c.rate > 0.0 ? c.rate : kDefaultSupportRate / c.radius;
  const T stabilised = G.g[3].d + 4.0 * w * G.g[3].v + 6.0 * w * w * G.g[2].v + 4.0 * w * w * w * G.g[1].v +
                       w * w * w * w * G.g[0].v;
  const T t_rho = G.g[1].v;
  *direction = {{G.e[0].v, G.e[1].v, G.e[2].v}};
  return -B * stabilised / (1.0 - t_rho * t_rho);
}

}  // namespace kirchhoff::detail
