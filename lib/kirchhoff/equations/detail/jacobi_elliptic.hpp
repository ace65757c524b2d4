// Internal: Jacobi's elliptic functions sn, cn, dn and his epsilon function of one argument u at
// a parameter 0 <= m < 1, by the arithmetic-geometric mean (Abramowitz & Stegun 16.4 and 17.6),
// written for any arithmetic type T: on Dual<N> the same steps give their derivatives with
// respect to whatever u and m depend on (the exact planar flow's Jacobian, elastica_flow.hpp).
//
// The AGM's c_n are formed as c_{n+1} = c_n^2 / (4 a_{n+1}), not (a_n - b_n) / 2, so that they
// keep their relative accuracy (and their derivatives) however small m is: c_1 = m / (2 (1 + b_0)).
// m = 0 is sin, cos and 1 exactly, its derivatives with respect to m included.
#pragma once

#include <cmath>

#include "kirchhoff/equations/detail/dual.hpp"

namespace kirchhoff::detail {

template <class T>
struct JacobiValues {
  T sn, cn, dn;
  // epsilon(u) = int_0^u dn^2 = E(am u | m), as u (E/K) + Z(u) (Jacobi's zeta function).
  T epsilon_minus_u_over_m;  // (u - epsilon(u)) / m = int_0^u sn^2, formed without dividing by m
};

// The AGM needs at most a handful of steps below m = 1 - 1e-12 (b_0 = 1e-6): c_n falls
// quadratically. kMaxSteps is a guard, not a tolerance.
constexpr int kJacobiMaxSteps = 40;

// At u and m; complement = 1 - m, which the caller can often form more accurately than by the
// subtraction (near m = 1 it sets b_0 = sqrt(1 - m) and with it the whole mean).
template <class T>
JacobiValues<T> jacobi_elliptic(const T& u, const T& m, const T& complement) {
  using std::asin;
  using std::cos;
  using std::sin;
  using std::sqrt;
  T a[kJacobiMaxSteps + 1], c_over_m[kJacobiMaxSteps + 1], c[kJacobiMaxSteps + 1];
  // n = 0: a = 1, b = sqrt(1 - m), c = sqrt(m) (c_0 enters only as c_0^2 = m).
  T b = sqrt(complement);
  a[0] = T(1.0);
  c_over_m[0] = T(0.0);
  c[0] = T(0.0);
  // 1 - E/K = (1/2) sum_n 2^n c_n^2; its n = 0 term over m is 1/2.
  T one_minus_e_over_k_over_m = T(0.5);
  int steps = 0;
  double scale = 1.0;  // 2^n
  while (steps < kJacobiMaxSteps) {
    const T a_next = 0.5 * (a[steps] + b);
    const T c_next_over_m = steps == 0 ? 1.0 / (4.0 * a_next) : c[steps] * c_over_m[steps] / (4.0 * a_next);
    const T c_next = c_next_over_m * m;
    b = sqrt(a[steps] * b);
    ++steps;
    scale *= 2.0;
    a[steps] = a_next;
    c[steps] = c_next;
    c_over_m[steps] = c_next_over_m;
    one_minus_e_over_k_over_m += 0.5 * scale * c_next * c_next_over_m;
    // A relative c_N below round-off: phi_N = 2^N a_N u holds sn to it. (The derivatives of the
    // c_n fall as fast: d c_{n+1} = c_n d c_n / (2 a_{n+1}) + ...)
    if (std::abs(value(c_next)) <= 1e-17 * std::abs(value(a_next))) break;
  }
  // Descend: phi_N = 2^N a_N u, phi_{n-1} = (phi_n + asin(c_n / a_n sin phi_n)) / 2 (A&S 16.4);
  // the zeta function is sum_{n>=1} c_n sin phi_n on these phi_n (A&S 17.6), here over m
  // (checked against GSL's E in tests/elastica_flow_test.cpp).
  T phi = scale * a[steps] * u;
  T zeta_over_m = T(0.0);
  for (int n = steps; n >= 1; --n) {
    const T sin_phi = sin(phi);
    zeta_over_m += c_over_m[n] * sin_phi;
    phi = 0.5 * (phi + asin(c[n] / a[n] * sin_phi));
  }
  JacobiValues<T> out;
  out.sn = sin(phi);
  out.cn = cos(phi);
  // dn^2 = 1 - m sn^2 = cn^2 + (1 - m) sn^2: the sum keeps dn's relative accuracy where it is
  // small (m near 1, sn near 1), which the difference loses to cancellation, and has no 0 / 0
  // at cn = 0 as A&S 16.4.3's cn / cos(phi_1 - phi_0) has.
  out.dn = sqrt(out.cn * out.cn + complement * out.sn * out.sn);
  out.epsilon_minus_u_over_m = u * one_minus_e_over_k_over_m - zeta_over_m;
  return out;
}

}  // namespace kirchhoff::detail
