// Closed-form rod results (see analytic.hpp). GSL supplies the elliptic integrals, the Jacobi
// elliptic functions and the bracketing root solver.
//
// GSL conventions used here, easy to mix up:
//   gsl_sf_ellint_Kcomp(k), gsl_sf_ellint_Ecomp(k), gsl_sf_ellint_E(phi, k) take the MODULUS k;
//   gsl_sf_elljac_e(u, m, ...) takes the PARAMETER m = k^2.
// GSL's default error handler aborts, so every argument is checked before it reaches GSL.
#include "kirchhoff/analysis/analytic.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multiroots.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_sf_ellint.h>
#include <gsl/gsl_sf_elljac.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace kirchhoff::analytic {
namespace {

constexpr double kPi = M_PI;

// ---------------------------------------------------------------------------------------------
// Argument checks

[[noreturn]] void reject(const char* where, const char* name, const std::string& reason) {
  throw std::invalid_argument(std::string(where) + ": " + name + " " + reason);
}

void require_positive(const char* where, const char* name, double value) {
  if (!std::isfinite(value)) reject(where, name, "must be finite, got " + std::to_string(value));
  if (!(value > 0.0)) reject(where, name, "must be > 0, got " + std::to_string(value));
}

void require_finite(const char* where, const char* name, double value) {
  if (!std::isfinite(value)) reject(where, name, "must be finite, got " + std::to_string(value));
}

// theta0 = 0 is the straight rod (no deflection, k = 0); theta0 = pi closes the loop (k = 1,
// K(k) infinite). Both are limits, not members, of the first-mode family.
void require_end_slope(const char* where, double theta0) {
  if (!(theta0 > 0.0 && theta0 < kPi))
    reject(where, "theta0", "must lie in the open interval (0, pi), got " + std::to_string(theta0));
}

void require_index(const char* where, const char* name, int index) {
  if (index < 1) reject(where, name, "must be >= 1 (counted from 1), got " + std::to_string(index));
}

void check(const PinnedElastica& rod, const char* where) {
  require_positive(where, "L", rod.L);
  require_positive(where, "EI", rod.EI);
  require_end_slope(where, rod.theta0);
}

void check_arclength(const PinnedElastica& rod, const char* where, double s) {
  check(rod, where);
  if (!(s >= 0.0 && s <= rod.L))
    reject(where, "s", "must lie in [0, L] = [0, " + std::to_string(rod.L) + "], got " + std::to_string(s));
}

// ---------------------------------------------------------------------------------------------
// GSL wrappers

void require_gsl_success(int status, const char* what) {
  if (status != GSL_SUCCESS) throw std::runtime_error(std::string(what) + ": " + gsl_strerror(status));
}

double complete_K(double k) {
  gsl_sf_result r;
  require_gsl_success(gsl_sf_ellint_Kcomp_e(k, GSL_PREC_DOUBLE, &r), "gsl_sf_ellint_Kcomp_e");
  return r.val;
}

double complete_E(double k) {
  gsl_sf_result r;
  require_gsl_success(gsl_sf_ellint_Ecomp_e(k, GSL_PREC_DOUBLE, &r), "gsl_sf_ellint_Ecomp_e");
  return r.val;
}

// Incomplete integral of the second kind E(phi, k); GSL reduces phi modulo pi itself, so
// negative amplitudes and |phi| slightly above pi/2 are fine.
double incomplete_F(double phi, double k) {
  gsl_sf_result r;
  require_gsl_success(gsl_sf_ellint_F_e(phi, k, GSL_PREC_DOUBLE, &r), "gsl_sf_ellint_F_e");
  return r.val;
}

double incomplete_E(double phi, double k) {
  gsl_sf_result r;
  require_gsl_success(gsl_sf_ellint_E_e(phi, k, GSL_PREC_DOUBLE, &r), "gsl_sf_ellint_E_e");
  return r.val;
}

struct Jacobi {
  double sn, cn, dn;
};

Jacobi jacobi(double u, double k) {
  Jacobi j{};
  require_gsl_success(gsl_sf_elljac_e(u, k * k, &j.sn, &j.cn, &j.dn), "gsl_sf_elljac_e");
  return j;
}

// Root of f in [lo, hi] (f(lo), f(hi) of opposite signs) by Brent's method, to machine precision.
template <class F>
double brent_root(F f, double lo, double hi) {
  const double f_lo = f(lo), f_hi = f(hi);
  if (f_lo == 0.0) return lo;
  if (f_hi == 0.0) return hi;
  if ((f_lo > 0.0) == (f_hi > 0.0)) throw std::logic_error("brent_root: interval does not bracket a root");

  gsl_function fn;
  fn.function = [](double x, void* params) { return (*static_cast<F*>(params))(x); };
  fn.params = &f;
  std::unique_ptr<gsl_root_fsolver, decltype(&gsl_root_fsolver_free)> solver(
      gsl_root_fsolver_alloc(gsl_root_fsolver_brent), &gsl_root_fsolver_free);
  if (!solver) throw std::bad_alloc();
  require_gsl_success(gsl_root_fsolver_set(solver.get(), &fn, lo, hi), "gsl_root_fsolver_set");

  constexpr int kMaxIterations = 200;  // Brent needs a few dozen at most for these smooth roots
  for (int i = 0; i < kMaxIterations; ++i) {
    require_gsl_success(gsl_root_fsolver_iterate(solver.get()), "gsl_root_fsolver_iterate");
    const double a = gsl_root_fsolver_x_lower(solver.get());
    const double b = gsl_root_fsolver_x_upper(solver.get());
    if (gsl_root_test_interval(a, b, 0.0, 4.0 * DBL_EPSILON) == GSL_SUCCESS) break;
  }
  return gsl_root_fsolver_root(solver.get());
}

// ---------------------------------------------------------------------------------------------
// Small functions of the Greenhill analysis, accurate near u = 0

// sin(u) / u.
double sinc(double u) { return std::abs(u) < 1e-4 ? 1.0 - u * u / 6.0 : std::sin(u) / u; }

// (sin u - u cos u) / u^2 = sum_{n>=1} (-1)^(n+1) 2n u^(2n-1) / (2n+1)!. The closed form loses
// about eps / u^2 relative accuracy to cancellation, so small |u| uses the series.
double g_over_u2(double u) {
  if (std::abs(u) >= 0.5) return (std::sin(u) - u * std::cos(u)) / (u * u);
  double power_over_factorial = u / 6.0;  // u^(2n-1) / (2n+1)! at n = 1
  double sum = 0.0, sign = 1.0;
  for (int n = 1; n <= 10; ++n) {  // at |u| = 0.5 the 10th term is below 1e-30
    sum += sign * 2.0 * n * power_over_factorial;
    power_over_factorial *= u * u / ((2.0 * n + 2.0) * (2.0 * n + 3.0));
    sign = -sign;
  }
  return sum;
}

// Characteristic function of the clamped-clamped twisted rod; see clamped_twisted_critical_moment.
double clamped_characteristic(double u1, double u2) {
  const double g1 = u1 * u1 * g_over_u2(u1);  // sin u1 - u1 cos u1
  return sinc(u2) * g1 - u1 * std::sin(u1) * g_over_u2(u2);
}

}  // namespace

// =============================================================================================
// Pinned-pinned Elastica (Love, Treatise, ch. XIX, "the elastica")
//
// EI theta'' = -P sin(theta) is the pendulum equation. Its first integral (the invariant H of
// eq. 54 with kappa = 0 at the supports) is theta'^2 = 2 lambda^2 (cos theta - cos theta0). The
// substitution sin(theta/2) = k sn(u), cos(theta/2) = dn(u) with k = sin(theta0/2) turns it into
// u' = -lambda, i.e. u = K - lambda s with the phase fixed by theta(0) = theta0 (sn(K) = 1). Then
//   theta(L/2) = 0 needs lambda L / 2 = K, and theta(L) = -theta0 follows from sn(-K) = -1;
//   x' = cos theta = 2 dn^2(u) - 1   and  int dn^2 du = E(am u, k);
//   y' = sin theta = 2 k sn(u) dn(u)  and  int sn dn du = -cn(u),
// which integrate, from x(0) = y(0) = 0, to the x(s) and y(s) below.

double PinnedElastica::k() const {
  check(*this, "PinnedElastica::k");
  return std::sin(0.5 * theta0);
}

double PinnedElastica::lambda() const {
  check(*this, "PinnedElastica::lambda");
  return 2.0 * complete_K(k()) / L;
}

double PinnedElastica::load() const {
  const double lam = lambda();
  return lam * lam * EI;  // = 4 K(k)^2 EI / L^2
}

double PinnedElastica::y_max() const { return 2.0 * k() / lambda(); }

double PinnedElastica::kappa_max() const { return 2.0 * k() * lambda(); }

double PinnedElastica::end_to_end() const {
  check(*this, "PinnedElastica::end_to_end");
  const double kk = k();
  return L * (2.0 * complete_E(kk) / complete_K(kk) - 1.0);
}

double PinnedElastica::theta(double s) const {
  check_arclength(*this, "PinnedElastica::theta", s);
  const double kk = k(), lam = lambda();
  return 2.0 * std::asin(kk * jacobi(0.5 * lam * L - lam * s, kk).sn);
}

double PinnedElastica::kappa(double s) const {
  check_arclength(*this, "PinnedElastica::kappa", s);
  const double kk = k(), lam = lambda();
  return -2.0 * kk * lam * jacobi(0.5 * lam * L - lam * s, kk).cn;
}

double PinnedElastica::x(double s) const {
  check_arclength(*this, "PinnedElastica::x", s);
  const double kk = k(), lam = lambda();
  const Jacobi j = jacobi(0.5 * lam * L - lam * s, kk);
  // |u| <= K, where cn >= 0, so the amplitude am(u) is atan2(sn, cn) without branch tracking.
  const double amplitude = std::atan2(j.sn, j.cn);
  return 2.0 / lam * (complete_E(kk) - incomplete_E(amplitude, kk)) - s;
}

double PinnedElastica::y(double s) const {
  check_arclength(*this, "PinnedElastica::y", s);
  const double kk = k(), lam = lambda();
  return 2.0 * kk / lam * jacobi(0.5 * lam * L - lam * s, kk).cn;
}

double PinnedElastica::hamiltonian(double s) const {
  const double kap = kappa(s);  // checks s
  return 0.5 * EI * kap * kap - load() * std::cos(theta(s));
}

// =============================================================================================
// Eq. (54): H = 1/2 EI kappa^2 - P cos(theta) at a support (kappa = 0, theta = theta0) equals H
// at mid-span (theta = 0), so 1/2 EI kappa_max^2 = P (1 - cos theta0); moment balance about the
// support gives EI kappa = -P y, hence y_max = EI kappa_max / P.
// 1 - cos(theta0) is evaluated as 2 sin^2(theta0/2), which is exact algebra but free of the
// cancellation that costs eps/theta0^2 relative accuracy at small angles.

double eq54_kappa_max(double P, double EI, double theta0) {
  require_positive("eq54_kappa_max", "P", P);
  require_positive("eq54_kappa_max", "EI", EI);
  require_end_slope("eq54_kappa_max", theta0);
  const double one_minus_cos = 2.0 * std::pow(std::sin(0.5 * theta0), 2);
  return std::sqrt(2.0 * P / EI * one_minus_cos);
}

double eq54_y_max(double P, double EI, double theta0) {
  require_positive("eq54_y_max", "P", P);
  require_positive("eq54_y_max", "EI", EI);
  require_end_slope("eq54_y_max", theta0);
  const double one_minus_cos = 2.0 * std::pow(std::sin(0.5 * theta0), 2);
  return std::sqrt(2.0 * EI / P * one_minus_cos);
}

// =============================================================================================
// Euler buckling. For EI w'''' + P w'' = 0 with x^2 = P L^2 / EI the end conditions give
//   pinned-pinned  sin x = 0;  clamped-free  cos x = 0;  clamped-pinned  tan x = x;
//   clamped-clamped  2 (1 - cos x) - x sin x = 4 sin(x/2) (sin(x/2) - (x/2) cos(x/2)) = 0.
// The roots x_j of tan x = x lie in (j pi, j pi + pi/2), so in the clamped-clamped sequence the
// symmetric roots 2 j pi and antisymmetric roots 2 x_j in (2 j pi, 2 j pi + pi) strictly alternate.

double tan_x_equals_x_root(int n) {
  require_index("tan_x_equals_x_root", "n", n);
  // sin x - x cos x = cos x (tan x - x) has no pole; at n pi it is (-1)^(n+1) n pi and at
  // n pi + pi/2 it is (-1)^n, so the bracket holds exactly one sign change.
  const auto f = [](double x) { return std::sin(x) - x * std::cos(x); };
  return brent_root(f, n * kPi, n * kPi + 0.5 * kPi);
}

double euler_load_parameter(EulerEnds ends, int mode) {
  require_index("euler_load_parameter", "mode", mode);
  switch (ends) {
    case EulerEnds::PinnedPinned: return mode * kPi;
    case EulerEnds::ClampedFree: return (2.0 * mode - 1.0) * 0.5 * kPi;
    case EulerEnds::ClampedPinned: return tan_x_equals_x_root(mode);
    case EulerEnds::ClampedClamped: {
      const int j = (mode + 1) / 2;  // mode 2j-1: symmetric, mode 2j: antisymmetric
      return mode % 2 == 1 ? 2.0 * j * kPi : 2.0 * tan_x_equals_x_root(j);
    }
  }
  throw std::invalid_argument("euler_load_parameter: ends is not a valid EulerEnds value");
}

double euler_critical_load(EulerEnds ends, double EI, double L, int mode) {
  require_positive("euler_critical_load", "EI", EI);
  require_positive("euler_critical_load", "L", L);
  require_index("euler_critical_load", "mode", mode);
  const double x = euler_load_parameter(ends, mode);
  return x * x * EI / (L * L);
}

// =============================================================================================
// Vibrations of straight columns and beams (eq. 96)

double pinned_column_frequency(double EI, double P, double rho_s, double L, int mode) {
  const char* where = "pinned_column_frequency";
  require_positive(where, "EI", EI);
  require_finite(where, "P", P);
  require_positive(where, "rho_s", rho_s);
  require_positive(where, "L", L);
  require_index(where, "mode", mode);
  const double q = mode * kPi / L;
  const double omega2 = (EI * q * q * q * q - P * q * q) / rho_s;
  if (!(omega2 > 0.0))
    reject(where, "P", "must be below the mode's Euler load " + std::to_string(EI * q * q) + ", got " + std::to_string(P));
  return std::sqrt(omega2);
}

double beam_frequency_parameter(BeamEnds ends, int mode) {
  require_index("beam_frequency_parameter", "mode", mode);
  // Divided by cosh x, the characteristic functions are cos x +- 1/cosh x: on each interval
  // between consecutive multiples of pi the cosine runs monotonically from +-1 to -+1 and 1/cosh
  // is below 0.1 past pi, so each interval holds exactly one root.
  if (ends == BeamEnds::ClampedFree)
    return brent_root([](double x) { return std::cos(x) + 1.0 / std::cosh(x); }, (mode - 1) * kPi, mode * kPi);
  return brent_root([](double x) { return std::cos(x) - 1.0 / std::cosh(x); }, mode * kPi, (mode + 1) * kPi);
}

double beam_frequency(BeamEnds ends, double EI, double rho_s, double L, int mode) {
  const char* where = "beam_frequency";
  require_positive(where, "EI", EI);
  require_positive(where, "rho_s", rho_s);
  require_positive(where, "L", L);
  const double x = beam_frequency_parameter(ends, mode);
  return x * x * std::sqrt(EI / rho_s) / (L * L);
}

double clamped_column_frequency(double EI, double P, double rho_s, double L, int mode) {
  const char* where = "clamped_column_frequency";
  require_positive(where, "EI", EI);
  require_finite(where, "P", P);
  require_positive(where, "rho_s", rho_s);
  require_positive(where, "L", L);
  require_index(where, "mode", mode);
  if (!(P < 4.0 * kPi * kPi * EI / (L * L)))
    reject(where, "P", "must be below the clamped-clamped Euler load 4 pi^2 EI / L^2, got " + std::to_string(P));
  // Parametrised by x = b L: (a L)^2 = x^2 - P L^2 / EI > 0 and omega = a b sqrt(EI / rhoS).
  const double p = P * L * L / EI;
  const double x_min = std::sqrt(std::max(p, 0.0));
  auto aL = [p](double x) { return std::sqrt(x * x - p); };
  // The characteristic function divided by cosh(a L), so that it stays O(1).
  auto characteristic = [&](double x) {
    const double a = aL(x);
    return 2.0 * a * x * (1.0 / std::cosh(a) - std::cos(x)) + (a * a - x * x) * std::tanh(a) * std::sin(x);
  };
  // a = 0 is a trivial root: start above it, where the sign is resolved (at P = 0 the function
  // is ~(b L)^6 / 3 there, computed from terms of size ~(b L)^4 / 6: 1e-3 keeps it clear of round-off;
  // frequencies below ~1e-3 sqrt(EI / rhoS) / L^2 are out of reach). Roots are about pi apart in
  // b L, far more than the scan step.
  constexpr double kScanStep = 0.05;
  constexpr double kStart = 1e-3;
  double lo = x_min + kStart, f_lo = characteristic(lo);
  int found = 0;
  for (int i = 1; i < 1000000; ++i) {
    const double hi = x_min + kStart + i * kScanStep, f_hi = characteristic(hi);
    if ((f_lo > 0.0) != (f_hi > 0.0) && ++found == mode) {
      const double x = brent_root(characteristic, lo, hi);
      return aL(x) * x * std::sqrt(EI / rho_s) / (L * L);
    }
    lo = hi;
    f_lo = f_hi;
  }
  throw std::runtime_error("clamped_column_frequency: root not found");
}

// =============================================================================================
// Straight twisted rod: m = C u3 e3 with uniform twist u3 = phi / L; n = T e3.

double StraightTwistedRod::twisting_moment() const {
  const char* where = "StraightTwistedRod::twisting_moment";
  require_positive(where, "B", B);
  require_positive(where, "C", C);
  require_positive(where, "L", L);
  require_finite(where, "phi", phi);
  require_finite(where, "T", T);
  return C * phi / L;
}

double StraightTwistedRod::hamiltonian() const {
  const double m3 = twisting_moment();  // checks the fields
  return 0.5 * m3 * m3 / C + T;
}

// =============================================================================================
// Greenhill problem, clamped-clamped, with tension.
//
// Linearisation. Let the rod lie along e3 with lateral displacement w(s) = x + i y (complex),
// twisting moment M and tension T. To first order in w, the moment is m = B e3 x r'' + M r'
// (bending plus the twisting moment carried along the tilted tangent) and n = T e3 + N, N a
// constant shear force. Moment balance m' + r' x n = 0 gives
//   B e3 x r''' + M r'' + e3 x N + T r' x e3 = 0.
// Cross with e3 (e3 x (e3 x a) = -a for a normal to e3; e3 x (.) is multiplication by i):
//   -B w''' + i M w'' + T w' = N   =>   B w'''' - i M w''' - T w'' = 0.
// (Reversing M only conjugates the problem, so the critical |M| does not depend on its sign.)
//
// Characteristic equation. With xi = s / L, m = M L / B, t = T L^2 / B the exponents are
// rho^2 (rho^2 - i m rho - t) = 0: rho = 0 (double) and rho = i w1, i w2, where
//   w1 + w2 = m,  w1 w2 = t,  w1,2 = m/2 +- beta,  beta = sqrt(m^2/4 - t).
// An energy argument fixes the regime. The equation is the Euler-Lagrange equation of the second
// variation Q[w] = int B|w''|^2 + T|w'|^2 - M Im(conj(w') w'') ds, and a clamped solution has
// Q = 0. For T > 0, Cauchy-Schwarz and AM-GM (|.| the L2 norm) give |M int Im(conj(w') w'')|
// <= M |w'| |w''| <= M / (2 sqrt(B T)) (B |w''|^2 + T |w'|^2), so Q > 0 for w != 0 while
// M < 2 sqrt(B T): the critical moment has m^2 >= 4 t. With T <= 0 that holds trivially. So beta
// is real and w1, w2 are real helical wavenumbers.
// With w = a + b xi + c e^(i w1 xi) + d e^(i w2 xi), w(0) = w'(0) = 0 eliminate a and b, and
// w(1) = w'(1) = 0 leave a 2x2 system whose determinant, multiplied by e^(-i m/2), is
//   D = -2i F,  F = 4 [u2 sin(u2) g(u1) - u1 sin(u1) g(u2)],  u_j = w_j / 2,
//   g(u) = sin u - u cos u.
// F is real; a nontrivial clamped solution exists iff F = 0. Two zeros of F are artefacts of a
// degenerate basis, not buckling modes:
//   * t = 0 (w2 = 0, triple root rho = 0): F = O(u2^2). Dividing by 4 u2^2 gives
//       Phi(u1, u2) = sinc(u2) g(u1) - u1 sin(u1) g(u2) / u2^2,
//     smooth in u2, and at t = 0 Phi = g(m/2): tan(m/2) = m/2, so m = 2 x_1 as expected.
//   * beta = 0 (w1 = w2): F vanishes identically there since it is odd under w1 <-> w2; the
//     energy argument shows that point is stable, so the search starts above it.
// Expanding g, F/4 = u1 u2 sin(beta) - beta sin(u1) sin(u2) = t/4 sin(beta) - beta sin(u1) sin(u2),
// so for large t the root is sin(beta) = O(beta / t): beta = pi + O(1/t), and
//   M = 2 sqrt(B T + pi^2 B^2 / L^2) (1 + O(t^-2)) -> 2 sqrt(B T),
// Greenhill's value for the long rod (the O(t^-2) term is below 4 pi^2 / t^2 to leading order).
//
// Search variable. For t > 0 the root sits at beta in (pi, x_1) (numerically), while m crowds
// against 2 sqrt(t), so beta is the variable. For t <= 0 the root m falls from 2 x_1 (t = 0) to 0
// at the clamped-clamped Euler load t = -4 pi^2, so m is the variable, starting at m = 0 where
// Phi is nonzero for -4 pi^2 < t < 0. Either way a fine scan finds the first sign change and
// Brent's method polishes it; w2 is computed as t / w1 to avoid cancellation in m/2 - beta.

double clamped_twisted_critical_moment(double B, double T, double L) {
  const char* where = "clamped_twisted_critical_moment";
  require_positive(where, "B", B);
  require_positive(where, "L", L);
  require_finite(where, "T", T);
  const double t = T * L * L / B;
  if (!(t > -4.0 * kPi * kPi))
    reject(where, "T", "must exceed -4 pi^2 B / L^2 (compression at or past the clamped-clamped Euler load), got " +
                           std::to_string(T));

  // m = M L / B as a function of the search variable v, and the characteristic function of v.
  const bool by_beta = t > 0.0;
  const auto moment_of = [t, by_beta](double v) { return by_beta ? 2.0 * std::sqrt(v * v + t) : v; };
  const auto characteristic = [t, by_beta](double v) {
    const double half_m = by_beta ? std::sqrt(v * v + t) : 0.5 * v;
    const double beta = by_beta ? v : std::sqrt(half_m * half_m - t);
    const double w1 = half_m + beta;
    const double w2 = w1 > 0.0 ? t / w1 : 0.0;
    return clamped_characteristic(0.5 * w1, 0.5 * w2);
  };

  // Step well below the spacing of the roots (about pi in beta or m), so none is stepped over.
  constexpr double kStep = 0.01;
  constexpr double kLimit = 100.0;  // the first root lies below 2 x_1 ~ 9 in either variable
  double v = t < 0.0 ? 0.0 : kStep;
  double f = characteristic(v);
  for (; v < kLimit; v += kStep) {
    const double f_next = characteristic(v + kStep);
    if (f == 0.0) return moment_of(v) * B / L;
    if ((f > 0.0) != (f_next > 0.0)) return moment_of(brent_root(characteristic, v, v + kStep)) * B / L;
    f = f_next;
  }
  throw std::runtime_error("clamped_twisted_critical_moment: no root found (t = " + std::to_string(t) + ")");
}

namespace {

// E(u) = E(am u, k) for any real u, continued through the quarter periods: the amplitude is
// unwrapped from atan2(sn, cn) and each half period adds 2 E(k).
double jacobi_epsilon(double u, double k, double sn, double cn) {
  const double K = gsl_sf_ellint_Kcomp(k, GSL_PREC_DOUBLE);
  const double n = std::floor((u + K) / (2.0 * K));  // half periods away from (-K, K]
  double am = std::atan2(sn, cn);                      // in (-pi, pi]
  // Bring am into (-pi/2, pi/2] consistently with the half-period count.
  am -= n * M_PI;
  while (am > M_PI / 2) am -= M_PI;
  while (am <= -M_PI / 2) am += M_PI;
  return 2.0 * n * gsl_sf_ellint_Ecomp(k, GSL_PREC_DOUBLE) + gsl_sf_ellint_E(am, k, GSL_PREC_DOUBLE);
}

struct WallProblem {
  double half, EI, x_end, y_end;
};

// Position and angle of the half rod at arclength s for the unknowns v = (lambda, psi, k, u0).
void wall_shape(const double* v, double s, double* x, double* y, double* theta, double* kappa) {
  const double lambda = v[0], psi = v[1], k = v[2], u0 = v[3];
  const double m = k * k;
  double sn0, cn0, dn0, sn, cn, dn;
  gsl_sf_elljac_e(u0, m, &sn0, &cn0, &dn0);
  gsl_sf_elljac_e(u0 + lambda * s, m, &sn, &cn, &dn);
  // In the frame of the force: xi' = 1 - 2 k^2 sn^2, eta' = 2 k sn dn.
  const double xi = (2.0 * (jacobi_epsilon(u0 + lambda * s, k, sn, cn) - jacobi_epsilon(u0, k, sn0, cn0)) - lambda * s) / lambda;
  const double eta = -2.0 * k * (cn - cn0) / lambda;
  *x = std::cos(psi) * xi - std::sin(psi) * eta;
  *y = std::sin(psi) * xi + std::cos(psi) * eta;
  *theta = psi + 2.0 * std::asin(std::clamp(k * sn, -1.0, 1.0));
  *kappa = 2.0 * k * lambda * cn;
}

int wall_equations(const gsl_vector* v, void* params, gsl_vector* f) {
  const auto* p = static_cast<const WallProblem*>(params);
  const double* u = v->data;
  if (!(u[0] > 0) || !(std::abs(u[2]) < 1)) return GSL_EDOM;
  double x0, y0, t0, k0, x1, y1, t1, k1;
  wall_shape(u, 0.0, &x0, &y0, &t0, &k0);
  wall_shape(u, p->half, &x1, &y1, &t1, &k1);
  gsl_vector_set(f, 0, t0);
  gsl_vector_set(f, 1, t1);
  gsl_vector_set(f, 2, x1 - p->x_end);
  gsl_vector_set(f, 3, y1 - p->y_end);
  return GSL_SUCCESS;
}

}  // namespace

WallContactElastica wall_contact_elastica(double L, double EI, double Delta, double a) {
  require_positive("wall_contact_elastica", "L", L);
  require_positive("wall_contact_elastica", "EI", EI);
  if (!(Delta > 0 && Delta < L)) throw std::invalid_argument("wall_contact_elastica: Delta must lie in (0, L)");
  WallProblem problem{L / 2, EI, (L - Delta) / 2, a};
  // Guess: the first clamped-clamped mode y = (a/2)(1 - cos 2 pi s/L) on the half rod, as a
  // pendulum with F = 4 pi^2 EI/L^2 along x (psi = 0), small k from its slope amplitude, and
  // the curvature's zero (u = K) at the quarter point.
  const double lambda = 2.0 * M_PI / L;
  const double k = std::sin(0.5 * M_PI * a / L);
  const double K = gsl_sf_ellint_Kcomp(k, GSL_PREC_DOUBLE);
  double guess[4] = {lambda, 0.0, k, K - lambda * L / 4};
  gsl_multiroot_function f{&wall_equations, 4, &problem};
  std::unique_ptr<gsl_multiroot_fsolver, decltype(&gsl_multiroot_fsolver_free)> solver(
      gsl_multiroot_fsolver_alloc(gsl_multiroot_fsolver_hybrids, 4), &gsl_multiroot_fsolver_free);
  gsl_vector_view x = gsl_vector_view_array(guess, 4);
  gsl_multiroot_fsolver_set(solver.get(), &f, &x.vector);
  int status = GSL_CONTINUE;
  for (int it = 0; it < 500 && status == GSL_CONTINUE; ++it) {
    if (gsl_multiroot_fsolver_iterate(solver.get()) != GSL_SUCCESS) break;
    status = gsl_multiroot_test_residual(solver.get()->f, 1e-14);
  }
  if (status != GSL_SUCCESS) throw std::runtime_error("wall_contact_elastica: the root finder did not converge");
  const double* v = solver.get()->x->data;
  WallContactElastica out;
  const double F = EI * v[0] * v[0];
  out.P = F * std::cos(v[1]);
  out.n_y = -F * std::sin(v[1]);
  out.contact_force = -2.0 * out.n_y;
  double xs, ys, ts;
  wall_shape(v, 0.0, &xs, &ys, &ts, &out.kappa_0);
  wall_shape(v, L / 2, &xs, &ys, &ts, &out.kappa_c);
  out.H = 0.5 * EI * out.kappa_0 * out.kappa_0 - out.P;
  return out;
}

double clamped_clamped_elastica_load(double EI, double L, double D) {
  const char* where = "clamped_clamped_elastica_load";
  require_positive(where, "EI", EI);
  require_positive(where, "L", L);
  if (!(D > 0.0 && D < L)) reject(where, "D", "must be in (0, L), got " + std::to_string(D));
  // 2E/K - 1 falls from 1 (k = 0) through 0 (k ~ 0.909); D/L in (0, 1) has one root there.
  const double k = brent_root([&](double k) { return 2.0 * complete_E(k) / complete_K(k) - 1.0 - D / L; }, 0.0, 0.9);
  const double K = complete_K(k);
  return 16.0 * K * K * EI / (L * L);
}

namespace {
void require_helix(const char* where, double theta, double EI, double R) {
  if (!(theta > 0.0 && theta < 0.25 * kPi)) reject(where, "theta", "must be in (0, pi/4), got " + std::to_string(theta));
  require_positive(where, "EI", EI);
  require_positive(where, "R", R);
}
}  // namespace

double helix_contact_pressure(double theta, double EI, double R) {
  return helix_tension(theta, EI, R) / R;  // (58a) = (58c) / R
}

double helix_twisting_moment(double theta, double EI, double R) {
  require_helix("helix_twisting_moment", theta, EI, R);
  return EI / R * 2.0 * std::pow(std::sin(theta), 3) * std::cos(theta) / std::cos(2.0 * theta);
}

double helix_tension(double theta, double EI, double R) {
  require_helix("helix_tension", theta, EI, R);
  return EI / (R * R) * std::pow(std::sin(theta), 4) / std::cos(2.0 * theta);
}

double plectoneme_end_tension(double theta, double EI, double R) {
  require_helix("plectoneme_end_tension", theta, EI, R);
  return 0.5 * EI / (R * R) * std::pow(std::sin(theta), 4) * (1.0 + 2.0 / std::cos(2.0 * theta));
}

namespace {

// The clamped-clamped rod on the wall with H = -P (see FlatContactBuckling): the outer arcs are
// full inflectional waves of two half-waves of length s_h each, with end slope alpha to the line
// of force. The flat part has the length flat_length(mu) (mu = sqrt(EI / P)); 4 s_h + l = L fixes
// mu for each alpha, and the arcs' height a fixes alpha.
template <class FlatLength>
FlatContactBuckling flat_wall_contact(const char* where, double L, double EI, double a, FlatLength flat_length) {
  require_positive(where, "L", L);
  require_positive(where, "EI", EI);
  require_positive(where, "a", a);
  if (!(a < L / 6.0)) reject(where, "a", "must be below L / 6");
  struct Shape {
    double mu, s_h, chord;
  };
  auto shape = [&](double alpha) {
    const double k = std::sin(0.5 * alpha), K = complete_K(k), E = complete_E(k);
    const double root_cos = std::sqrt(std::cos(alpha));
    // 4 s_h + l(mu) = L with s_h = 2 K mu sqrt(cos alpha) and l linear in mu.
    const double mu = L / (8.0 * K * root_cos + flat_length(1.0));
    const double s_h = 2.0 * K * mu * root_cos;
    return Shape{mu, s_h, 2.0 * s_h * (2.0 * E / K - 1.0)};
  };
  // The height grows monotonically from 0 (alpha -> 0, a straight rod) to ~0.19 L near alpha = 1
  // (beyond, the chord shrinks: 2E/K - 1 -> 0 near alpha = 130 deg); the root is below 1 rad.
  const double alpha = brent_root([&](double al) { return shape(al).chord * std::sin(al) - a; }, 1e-9, 1.0);
  const Shape s = shape(alpha);
  FlatContactBuckling out;
  out.alpha = alpha;
  out.P = EI / (s.mu * s.mu);
  out.flat_length = flat_length(s.mu);
  out.contact_start = 2.0 * s.s_h;
  out.Delta = L - out.flat_length - 2.0 * s.chord * std::cos(alpha);
  return out;
}

}  // namespace

FlatContactBuckling flat_contact_buckling(double L, double EI, double a) {
  // The flat part at its clamped-clamped Euler load: l = 2 pi mu.
  return flat_wall_contact("flat_contact_buckling", L, EI, a, [](double mu) { return 2.0 * M_PI * mu; });
}

FlatContactBuckling contact_flattening(double L, double EI, double a) {
  // A flat part of zero length: the point contact at mid-span with kappa_c = 0.
  return flat_wall_contact("contact_flattening", L, EI, a, [](double) { return 0.0; });
}

SecondModeArches second_mode_arches(double L, double EI, double a) {
  const char* where = "second_mode_arches";
  require_positive(where, "L", L);
  require_positive(where, "EI", EI);
  require_positive(where, "a", a);
  if (!(a < 0.2 * L)) reject(where, "a", "must be below 0.2 L");
  // 2 y_max = 2 k L / (4 K(k)) grows monotonically with theta0 on (0, 2), to 0.2016 L.
  auto crest = [&](double theta0) { return 2.0 * PinnedElastica{0.25 * L, EI, theta0}.y_max() - a; };
  SecondModeArches out;
  out.theta0 = brent_root(crest, 1e-9, 2.0);
  const PinnedElastica quarter{0.25 * L, EI, out.theta0};
  out.P = quarter.load();
  out.Delta = L - 4.0 * quarter.end_to_end();
  return out;
}

ThreePointBending three_point_bending(double L, double EI, double theta_end) {
  const char* where = "three_point_bending";
  require_positive(where, "L", L);
  require_positive(where, "EI", EI);
  if (!(theta_end > -M_PI / 2 && theta_end < 0.0)) reject(where, "theta_end", "must lie in (-pi/2, 0)");
  const double k = std::sin(0.5 * (M_PI / 2 - theta_end));
  const double psi1 = std::asin(1.0 / (std::sqrt(2.0) * k));
  const double dF = complete_K(k) - incomplete_F(psi1, k);
  const double dE = complete_E(k) - incomplete_E(psi1, k);
  ThreePointBending out;
  const double half_load = EI * std::pow(dF / (0.5 * L), 2);  // F/2
  out.force = 2.0 * half_load;
  out.rise = std::sqrt(EI / half_load) * (dF - 2.0 * dE);
  out.half_span = std::sqrt(2.0 * EI * (2.0 * k * k - 1.0) / half_load);
  out.kappa_mid = -std::sqrt(2.0 * half_load * (-std::sin(theta_end)) / EI);
  return out;
}

WrappedThreePointBending three_point_bending_wrapped(double L, double EI, double radius, double theta_end) {
  const char* where = "three_point_bending_wrapped";
  require_positive(where, "L", L);
  require_positive(where, "EI", EI);
  require_positive(where, "radius", radius);
  if (!(theta_end > -M_PI / 2 && theta_end < 0.0)) reject(where, "theta_end", "must lie in (-pi/2, 0)");
  const double phi_e = -theta_end;
  const double k = std::sin(0.5 * (M_PI / 2 + phi_e));
  const double K = complete_K(k), E = complete_E(k);
  struct Arc {
    double alpha, psi, scale;  // wrap angle, its elliptic amplitude, sqrt(EI / R0)
  };
  const auto arc = [&](double R0) {
    const double alpha = std::asin(std::sin(phi_e) - EI / (2.0 * R0 * radius * radius));
    return Arc{alpha, std::asin(std::min(1.0, std::sin(0.5 * (M_PI / 2 + alpha)) / k)), std::sqrt(EI / R0)};
  };
  const auto excess = [&](double R0) {  // l + rho alpha - L/2
    const Arc a = arc(R0);
    return a.scale * (K - incomplete_F(a.psi, k)) + radius * a.alpha - 0.5 * L;
  };
  const double onset = EI / (2.0 * radius * radius * std::sin(phi_e));  // R0 where alpha = 0
  if (!(excess(onset) > 0.0))
    reject(where, "radius", "is too small for the rod to wrap at this support slope (the point contact's curvature stays below 1/radius)");
  if (!(radius * phi_e < 0.5 * L)) reject(where, "radius", "is too large: the wrap alone would be longer than the rod");
  double hi = 2.0 * onset;
  while (excess(hi) > 0.0) hi *= 2.0;
  const double R0 = brent_root(excess, onset, hi);
  const Arc a = arc(R0);
  WrappedThreePointBending out;
  out.force = 2.0 * R0;
  out.wrap_angle = a.alpha;
  out.contact_start = a.scale * (K - incomplete_F(a.psi, k));
  out.half_span = radius * std::sin(a.alpha) + EI / (radius * R0);
  out.rise = radius * (1.0 - std::cos(a.alpha)) +
             a.scale * ((K - incomplete_F(a.psi, k)) - 2.0 * (E - incomplete_E(a.psi, k)));
  out.tension = R0 * std::sin(a.alpha);
  out.edge_force = R0 * std::cos(a.alpha);
  return out;
}

double michell_ring_critical_twist(double B, double C, double R, int mode) {
  const char* where = "michell_ring_critical_twist";
  require_positive(where, "B", B);
  require_positive(where, "C", C);
  require_positive(where, "R", R);
  if (mode < 2) reject(where, "mode", "must be >= 2 (mode 1 is a rigid turn of the ring), got " + std::to_string(mode));
  const double n = mode;
  return std::sqrt(n * n - 1.0) * B / (C * R);
}

}  // namespace kirchhoff::analytic
