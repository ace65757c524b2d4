// Internal: the exact flow of a planar rod whose only load is the force at its ends: uniform,
// inextensible, without a field, of constant natural curvature and strain. Its moment obeys the
// pendulum equation, B theta'' = |n~| sin(theta - alpha), and the state at s0 + ds is closed
// form in Jacobi's elliptic functions of lambda ds, lambda^2 = |n~| / B (Love's kinetic analogue):
// a few dozen operations where a Runge-Kutta march at 1e-12 takes some six hundred right-hand
// sides. Written for any arithmetic type T, so that Dual<N> gives Phi exactly.
//
// With psi = theta - alpha - pi (zero where the rod points against the force), S = sin(psi / 2),
// D = cos(psi / 2), C = psi' / (2 lambda): the oscillating regime, where the parameter
// m = S^2 + C^2 < 1, has S = k sn(u), C = k cn(u), D = dn(u), u = lambda s + u_0, and the
// addition theorems give S, C, D at u_0 + lambda ds from their values at s0 and sn, cn, dn of
// lambda ds alone, so u_0 (an inverse elliptic function) is never formed, and m -> 0 (a straight
// rod on its equilibrium) is regular. The position is the integral of r' = (v3 + i v1) e^{i theta}
// (complex notation in the plane), from the integrals of cos psi = 1 - 2 S^2 and sin psi = 2 S D.
//
// Outside that regime (a rod that turns over, the separatrix between, no force), and nearer the
// separatrix or over shorter phases than the limits below allow, the flow is not formed here:
// the caller marches.
#pragma once

#include <cmath>
#include <type_traits>

#include "kirchhoff/equations/detail/dual.hpp"
#include "kirchhoff/equations/detail/jacobi_elliptic.hpp"
#include "kirchhoff/equations/detail/planar_state.hpp"

namespace kirchhoff::detail {

struct ElasticaConstants {
  double bending = 1.0;    // B
  double curvature = 0.0;  // the natural curvature u_hat_2
  double v1 = 0.0, v3 = 1.0;  // the natural strains (body frame): r' = v1 d1 + v3 d3
};

// Where the closed form is used, as the flow's orbit (1 - m, below the separatrix) and phase
// v = lambda |ds| allow. Its derivatives lose digits that a march keeps as 1 - m falls (those with
// respect to m grow like 1 / (1 - m) and cancel) and as v falls (the force's direction enters
// through n / |n|, and the position's derivatives with respect to it, O(ds / |n|) each, cancel to
// the flow's O(ds^3 / B): each column of Phi is good to about 1e-13 / v^2 of its size). Measured
// against RKF78 at 1e-13 and 1e-14 on random states (tests/elastica_flow_test.cpp samples them):
// with 1 - m >= 1e-2 and v >= 0.1 Phi agrees to 1.6e-11 of its size; with 1 - m in (1e-4, 1e-2),
// to 1.4e-10 of a column (the two marches to 1.5e-11 of each other); at v = 1e-3, 1e-8. The state keeps its accuracy much further: 1e-15 of its
// size down to v = 1e-7, and the Euler column's elliptic solution to 1e-14 down to 1 - m = 3e-5,
// where a march at 1e-12 has lost digits to the orbit's sensitivity (3e-10 in the residual of the
// column at P = 100, 1 - m = 7e-4).
struct ClosedFormLimits {
  double separatrix_margin;  // least 1 - m
  double least_phase;        // least lambda |ds|
};
// The state alone (residuals, profiles).
constexpr ClosedFormLimits kStateLimits{1e-4, 1e-6};
// Phi for shooting (Newton's matrices, tangents, the branch points' test functions: to about
// 1e-10 of a column, 3e-12 where 1 - m > 1e-2; the march's own Phi is good to ~1e-11 there).
constexpr ClosedFormLimits kMatrixLimits{1e-3, 0.1};
// Phi for the stability analysis' Jacobi fields, integrated to ~1e-10 otherwise.
constexpr ClosedFormLimits kFieldLimits{1e-3, 0.02};

// The Jacobi functions of the last flow, for the next one over the same phase on the same orbit
// (a profile's equal intervals: one AGM instead of one per sample). Reused where v agrees to
// 2e-15 of itself and m to 1e-12 of 1 - m: m, formed from each state, drifts by round-off along
// the orbit (by up to 1e-13 a step near the separatrix, where little is reused), and over 10 to
// 1000 steps the states then agree with flows that form their own functions to 1e-13 of a state
// of size 20 (tests/elastica_flow_test.cpp).
struct JacobiMemo {
  bool filled = false;
  double v = 0.0, m = 0.0;
  JacobiValues<double> values;
  int evaluations = 0;  // of jacobi_elliptic (the tests count them)

  static constexpr double kSamePhase = 2e-15;  // of v
  static constexpr double kSameOrbit = 1e-12;  // of 1 - m

  const JacobiValues<double>& at(double v_now, double m_now, double complement) {
    if (!filled || !(std::abs(v_now - v) <= kSamePhase * std::abs(v)) ||
        !(std::abs(m_now - m) <= kSameOrbit * complement)) {
      values = jacobi_elliptic(v_now, m_now, complement);
      v = v_now;
      m = m_now;
      filled = true;
      ++evaluations;
    }
    return values;
  }
};

// The functions of v and m on dual numbers of N > 2 directions by the chain rule through two: they
// depend on the state through v and m alone, so the mean runs on Dual<2> (d/dv, d/dm) and each
// result's N derivatives are d/dv dv + d/dm dm (the complement's derivative is -dm). The same
// numbers to round-off at a third of the operations on Dual<4> (Phi, the stability fields).
template <int N>
JacobiValues<Dual<N>> jacobi_through_v_and_m(const Dual<N>& v, const Dual<N>& m, const Dual<N>& complement) {
  Dual<2> v2(v.v), m2(m.v), complement2(complement.v);
  v2.d[0] = 1.0;
  m2.d[1] = 1.0;
  complement2.d[1] = -1.0;
  const JacobiValues<Dual<2>> j = jacobi_elliptic(v2, m2, complement2);
  auto chained = [&](const Dual<2>& x) {
    Dual<N> out(x.v);
    for (int k = 0; k < N; ++k) out.d[k] = x.d[0] * v.d[k] + x.d[1] * m.d[k];
    return out;
  };
  return {chained(j.sn), chained(j.cn), chained(j.dn), chained(j.epsilon_minus_u_over_m)};
}

template <class T>
struct DualDirections : std::integral_constant<int, 0> {};
template <int N>
struct DualDirections<Dual<N>> : std::integral_constant<int, N> {};

template <class T>
JacobiValues<T> jacobi_of_phase(const T& v, const T& m, const T& complement, JacobiMemo* memo) {
  if constexpr (std::is_same_v<T, double>) {
    if (memo) return memo->at(v, m, complement);
  } else if constexpr (DualDirections<T>::value > 2) {
    return jacobi_through_v_and_m(v, m, complement);
  }
  return jacobi_elliptic(v, m, complement);
}

// y1 = the state at s0 + ds from y0 (planar layout), or false (y1 untouched) where the rod is not
// in the oscillating regime the closed form covers, within `limits`. `memo` (double only, may be
// null) carries the Jacobi functions from one call to the next (JacobiMemo).
template <class T>
bool elastica_flow(const T* y0, double ds, const ElasticaConstants& rod, T* y1, const ClosedFormLimits& limits,
                   JacobiMemo* memo = nullptr) {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  // The force the pendulum feels: m' = Im(conj(n~) e^{i theta}), n~ = n (v3 - i v1).
  const T tx = y0[kNx] * rod.v3 + y0[kNy] * rod.v1;
  const T ty = y0[kNy] * rod.v3 - y0[kNx] * rod.v1;
  const T force2 = tx * tx + ty * ty;
  if (!(value(force2) > 0.0)) return false;
  const T force = sqrt(force2);
  const T lambda = sqrt(force / rod.bending);
  const T c = cos(y0[kTheta]), s = sin(y0[kTheta]);
  const T cos_psi = -(tx * c + ty * s) / force;
  const T sin_psi = -(tx * s - ty * c) / force;
  const T d0_squared = 0.5 * (1.0 + cos_psi);
  const T omega0 = rod.curvature + y0[kMoment] / rod.bending;  // theta' = psi'
  const T c0 = omega0 / (2.0 * lambda);
  const T complement = d0_squared - c0 * c0;  // 1 - m, as D^2 - C^2 (S^2 + D^2 = 1)
  if (!(value(complement) > limits.separatrix_margin)) return false;
  const T d0 = sqrt(d0_squared);
  const T s0 = sin_psi / (2.0 * d0);
  const T m = s0 * s0 + c0 * c0;
  const T v = lambda * ds;
  if (!(std::abs(value(v)) >= limits.least_phase)) return false;
  const JacobiValues<T> j = jacobi_of_phase(v, m, complement, memo);
  // 1 - S0^2 sn^2 as D0^2 + S0^2 cn^2: two terms of one sign, where the difference cancels to
  // 1 - m near the separatrix (1e-9 of the state lost at 1 - m = 2e-3 on long phases).
  const T den = d0_squared + s0 * s0 * j.cn * j.cn;
  const T s1 = (s0 * j.cn * j.dn + c0 * d0 * j.sn) / den;
  const T d1 = (d0 * j.dn - s0 * c0 * j.sn * j.cn) / den;
  // 1 - cn without cancellation on either side of cn = 0.
  const T one_minus_cn = value(j.cn) > 0.0 ? j.sn * j.sn / (1.0 + j.cn) : 1.0 - j.cn;
  const T c1_minus_c0 = (c0 * (s0 * s0 * j.sn * j.sn - one_minus_cn) - s0 * d0 * j.sn * j.dn) / den;
  const T c1 = c0 + c1_minus_c0;
  // psi stays in (-pi, pi) (D > 0): the turn is the difference of the half angles, doubled.
  y1[kTheta] = y0[kTheta] + 2.0 * atan2(s1 * d0 - d1 * s0, d1 * d0 + s1 * s0);
  y1[kMoment] = (2.0 * lambda * c1 - rod.curvature) * rod.bending;
  y1[kNx] = y0[kNx];
  y1[kNy] = y0[kNy];
  // int S^2 ds = (m int sn^2 du) / lambda over [u_0, u_0 + v], by the epsilon function's
  // addition theorem; int sin psi ds = -2 (C1 - C0) / lambda.
  const T int_s2 = (m * j.epsilon_minus_u_over_m) / lambda + s0 * s1 * j.sn / lambda;
  const T int_cos = ds - 2.0 * int_s2;
  const T int_sin = -2.0 * c1_minus_c0 / lambda;
  // r1 - r0 = (v3 + i v1) (-n~ / |n~|) (int_cos + i int_sin).
  const T ux = -tx / force, uy = -ty / force;
  const T ex = ux * int_cos - uy * int_sin, ey = ux * int_sin + uy * int_cos;
  y1[kX] = y0[kX] + rod.v3 * ex - rod.v1 * ey;
  y1[kY] = y0[kY] + rod.v3 * ey + rod.v1 * ex;
  return true;
}

}  // namespace kirchhoff::detail
