// Tests of the closed-form rod results in kirchhoff/analysis/analytic.hpp.
//
// Tolerances. GSL's K(k), E(k), E(phi, k) and sn/cn/dn are accurate to a few ulps (~1e-15
// relative) for the moduli used here (k <= sin 1.4 = 0.985); root solves are run to 4 eps.
// Tolerances on exact identities therefore sit at 1e-12, leaving a few hundred ulps for the
// chained operations, and tolerances on approximations follow the truncation error of the
// approximation (stated at each test).
#include "kirchhoff/analysis/analytic.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace kirchhoff::analytic;

constexpr double kPi = 3.14159265358979323846;
// First roots of tan x = x (Abramowitz & Stegun, Table 4.19, to 16 digits).
constexpr double kTanRoot1 = 4.493409457909064;
constexpr double kTanRoot2 = 7.725251836937707;
constexpr double kTanRoot3 = 10.904121659428899;

// Moderate to large end slopes; 2.8 rad is past the 130.7 deg at which the chord turns negative.
const std::vector<double> kEndSlopes = {0.3, 1.0, 2.0, 2.8};

PinnedElastica rod_with_slope(double theta0) { return PinnedElastica{2.0, 3.0, theta0}; }

// --------------------------------------------------------------------------------------------
// Pinned-pinned Elastica

// Eq. (54) is an exact consequence of the invariant H, so with P = load() it must reproduce the
// elliptic-function values up to rounding.
TEST(PinnedElastica, MatchesEq54) {
  for (double theta0 : kEndSlopes) {
    SCOPED_TRACE("theta0 = " + std::to_string(theta0));
    const PinnedElastica rod = rod_with_slope(theta0);
    const double P = rod.load();
    EXPECT_NEAR(rod.kappa_max(), eq54_kappa_max(P, rod.EI, theta0), 1e-12 * rod.kappa_max());
    EXPECT_NEAR(rod.y_max(), eq54_y_max(P, rod.EI, theta0), 1e-12 * rod.y_max());
    // The literal form of eq. 54 with 1 - cos(theta0); its cancellation costs eps / theta0^2
    // relative, below 3e-15 for theta0 >= 0.3.
    EXPECT_NEAR(rod.kappa_max(), std::sqrt(2.0 * P / rod.EI * (1.0 - std::cos(theta0))), 1e-12 * rod.kappa_max());
    EXPECT_NEAR(rod.y_max(), std::sqrt(2.0 * rod.EI / P * (1.0 - std::cos(theta0))), 1e-12 * rod.y_max());
    // Moment balance about a support: EI kappa_max = P y_max.
    EXPECT_NEAR(rod.EI * rod.kappa_max(), P * rod.y_max(), 1e-12 * P * rod.y_max());
  }
}

// Boundary and mid-span values. theta = 2 asin(k sn) amplifies sn's error by 1/cos(theta0/2),
// at most 6 here, so 1e-12 absolute is still a few hundred ulps.
TEST(PinnedElastica, EndAndMidSpanValues) {
  for (double theta0 : kEndSlopes) {
    SCOPED_TRACE("theta0 = " + std::to_string(theta0));
    const PinnedElastica rod = rod_with_slope(theta0);
    const double L = rod.L;
    EXPECT_NEAR(rod.theta(0.0), theta0, 1e-12);
    EXPECT_NEAR(rod.theta(L), -theta0, 1e-12);
    EXPECT_NEAR(rod.theta(0.5 * L), 0.0, 1e-12);
    // Pinned ends carry no moment.
    EXPECT_NEAR(rod.kappa(0.0), 0.0, 1e-12 * rod.kappa_max());
    EXPECT_NEAR(rod.kappa(L), 0.0, 1e-12 * rod.kappa_max());
    // The arch bulges to +y and turns clockwise: kappa(L/2) = -kappa_max.
    EXPECT_NEAR(rod.kappa(0.5 * L), -rod.kappa_max(), 1e-12 * rod.kappa_max());
    EXPECT_NEAR(rod.y(0.5 * L), rod.y_max(), 1e-12 * rod.y_max());
    EXPECT_NEAR(rod.x(0.0), 0.0, 1e-12 * L);
    EXPECT_NEAR(rod.y(0.0), 0.0, 1e-12 * L);
    EXPECT_NEAR(rod.y(L), 0.0, 1e-12 * L);
    // Absolute (in units of L) because the chord passes through zero near theta0 = 130.7 deg.
    EXPECT_NEAR(rod.x(L), rod.end_to_end(), 1e-12 * L);
    // Symmetry about mid-span.
    EXPECT_NEAR(rod.x(0.5 * L), 0.5 * rod.end_to_end(), 1e-12 * L);
  }
}

TEST(PinnedElastica, ChordChangesSignPastTheFigureEightAngle) {
  EXPECT_GT(rod_with_slope(2.0).end_to_end(), 0.0);
  EXPECT_LT(rod_with_slope(2.8).end_to_end(), 0.0);
}

// Central differences with h = 1e-5: truncation h^2 |f'''| / 6 < 1e-9 for these shapes
// (|f'''| <= kappa_max^2 + |kappa'| < 1e2), rounding ~ eps |f| / h ~ 1e-10; hence 1e-8.
TEST(PinnedElastica, ShapeSatisfiesTheElasticaEquations) {
  const double h = 1e-5;
  for (double theta0 : kEndSlopes) {
    SCOPED_TRACE("theta0 = " + std::to_string(theta0));
    const PinnedElastica rod = rod_with_slope(theta0);
    const double P = rod.load();
    for (int i = 1; i < 20; ++i) {
      const double s = rod.L * i / 20.0;
      SCOPED_TRACE("s = " + std::to_string(s));
      const auto d = [&](double (PinnedElastica::*f)(double) const) {
        return ((rod.*f)(s + h) - (rod.*f)(s - h)) / (2.0 * h);
      };
      EXPECT_NEAR(d(&PinnedElastica::x), std::cos(rod.theta(s)), 1e-8);
      EXPECT_NEAR(d(&PinnedElastica::y), std::sin(rod.theta(s)), 1e-8);
      EXPECT_NEAR(d(&PinnedElastica::theta), rod.kappa(s), 1e-8 * rod.kappa_max());
      // EI theta'' = -P sin(theta), i.e. the pinned support reaction n = -P e_x.
      EXPECT_NEAR(rod.EI * d(&PinnedElastica::kappa), -P * std::sin(rod.theta(s)), 1e-8 * P);
      // Bending moment = moment of the end load about the section: EI kappa = -P y.
      EXPECT_NEAR(rod.EI * rod.kappa(s), -P * rod.y(s), 1e-12 * P * rod.y_max());
    }
  }
}

// The Noether invariant behind eq. 54 is constant along the rod.
TEST(PinnedElastica, HamiltonianIsConstant) {
  for (double theta0 : kEndSlopes) {
    SCOPED_TRACE("theta0 = " + std::to_string(theta0));
    const PinnedElastica rod = rod_with_slope(theta0);
    const double P = rod.load();
    for (int i = 0; i <= 10; ++i)
      EXPECT_NEAR(rod.hamiltonian(rod.L * i / 10.0), -P * std::cos(theta0), 1e-12 * P);
  }
}

// K(k)^2 / (pi/2)^2 = 1 + k^2/2 + 11 k^4/32 + O(k^6) (series of K), with k^6 coefficient 0.27.
TEST(PinnedElastica, SmallSlopeLimitIsEulerLoad) {
  const double L = 1.5, EI = 0.8;
  const double euler = kPi * kPi * EI / (L * L);
  {
    const PinnedElastica rod{L, EI, 0.1};
    const double k = rod.k();
    const double series = 1.0 + k * k / 2.0 + 11.0 * std::pow(k, 4) / 32.0;
    EXPECT_NEAR(rod.load() / euler, series, std::pow(k, 6));
  }
  {
    // k^2 / 2 = 1.25e-13: the load is the Euler load to rounding.
    const PinnedElastica rod{L, EI, 1e-6};
    EXPECT_NEAR(rod.load() / euler, 1.0, 1e-12);
    EXPECT_NEAR(rod.load(), euler_critical_load(EulerEnds::PinnedPinned, EI, L), 1e-12 * euler);
    EXPECT_NEAR(rod.end_to_end(), L, 1e-12 * L);
  }
}

// --------------------------------------------------------------------------------------------
// Euler loads: the roots are solved to 4 eps, so 1e-14 relative on P = x^2 EI / L^2.

TEST(Euler, TanEqualsArgumentRoots) {
  EXPECT_NEAR(tan_x_equals_x_root(1), kTanRoot1, 1e-14 * kTanRoot1);
  EXPECT_NEAR(tan_x_equals_x_root(2), kTanRoot2, 1e-14 * kTanRoot2);
  EXPECT_NEAR(tan_x_equals_x_root(3), kTanRoot3, 1e-14 * kTanRoot3);
  for (int n = 1; n <= 50; ++n) {
    const double x = tan_x_equals_x_root(n);
    EXPECT_GT(x, n * kPi);
    EXPECT_LT(x, n * kPi + 0.5 * kPi);
    EXPECT_NEAR(std::sin(x) - x * std::cos(x), 0.0, 1e-13 * x);
  }
}

TEST(Euler, KnownLoads) {
  const double EI = 2.0, L = 3.0, scale = EI / (L * L);
  const auto expect_load = [&](EulerEnds ends, int mode, double x) {
    SCOPED_TRACE("mode " + std::to_string(mode));
    EXPECT_NEAR(euler_critical_load(ends, EI, L, mode), x * x * scale, 1e-14 * x * x * scale);
  };
  expect_load(EulerEnds::PinnedPinned, 1, kPi);
  expect_load(EulerEnds::PinnedPinned, 3, 3.0 * kPi);
  expect_load(EulerEnds::ClampedFree, 1, kPi / 2.0);
  expect_load(EulerEnds::ClampedFree, 2, 3.0 * kPi / 2.0);
  expect_load(EulerEnds::ClampedPinned, 1, kTanRoot1);  // 20.19073 EI / L^2
  expect_load(EulerEnds::ClampedPinned, 2, kTanRoot2);
  expect_load(EulerEnds::ClampedClamped, 1, 2.0 * kPi);  // 4 pi^2 EI / L^2
  expect_load(EulerEnds::ClampedClamped, 2, 2.0 * kTanRoot1);
  expect_load(EulerEnds::ClampedClamped, 3, 4.0 * kPi);
  expect_load(EulerEnds::ClampedClamped, 4, 2.0 * kTanRoot2);
  expect_load(EulerEnds::ClampedClamped, 5, 6.0 * kPi);
  // Textbook effective-length factor of the clamped-pinned column, K_eff = pi / x_1 = 0.6992.
  EXPECT_NEAR(kPi / euler_load_parameter(EulerEnds::ClampedPinned), 0.69915566, 1e-8);
}

TEST(Euler, ModesIncrease) {
  for (EulerEnds ends : {EulerEnds::PinnedPinned, EulerEnds::ClampedFree, EulerEnds::ClampedPinned,
                         EulerEnds::ClampedClamped}) {
    for (int mode = 1; mode < 30; ++mode)
      EXPECT_LT(euler_critical_load(ends, 1.0, 1.0, mode), euler_critical_load(ends, 1.0, 1.0, mode + 1));
  }
  // End conditions order the first load: clamped-free < pinned-pinned < clamped-pinned < clamped-clamped.
  EXPECT_LT(euler_critical_load(EulerEnds::ClampedFree, 1.0, 1.0), euler_critical_load(EulerEnds::PinnedPinned, 1.0, 1.0));
  EXPECT_LT(euler_critical_load(EulerEnds::PinnedPinned, 1.0, 1.0), euler_critical_load(EulerEnds::ClampedPinned, 1.0, 1.0));
  EXPECT_LT(euler_critical_load(EulerEnds::ClampedPinned, 1.0, 1.0), euler_critical_load(EulerEnds::ClampedClamped, 1.0, 1.0));
}

// --------------------------------------------------------------------------------------------
// Straight twisted rod

TEST(StraightTwistedRod, MomentAndHamiltonian) {
  const StraightTwistedRod rod{1.0, 0.75, 2.0, 3.0, 0.4};
  EXPECT_DOUBLE_EQ(rod.twisting_moment(), 0.75 * 3.0 / 2.0);
  EXPECT_DOUBLE_EQ(rod.hamiltonian(), 0.5 * 1.125 * 1.125 / 0.75 + 0.4);
}

// --------------------------------------------------------------------------------------------
// Greenhill: clamped-clamped twisted rod

// Independent check of the characteristic equation: the 4x4 clamped boundary matrix of the basis
// {1, xi, exp(rho1 xi), exp(rho2 xi)}, rho^2 - i m rho - t = 0, built and reduced here without
// the algebra used in analytic.cpp.
std::complex<double> clamped_boundary_determinant(double m, double t) {
  using C = std::complex<double>;
  const C disc = std::sqrt(C(4.0 * t - m * m, 0.0));
  const C r1 = (C(0.0, m) + disc) / 2.0, r2 = (C(0.0, m) - disc) / 2.0;
  // Rows: w(0), w'(0), w(1), w'(1).
  std::array<std::array<C, 4>, 4> a = {{{1.0, 0.0, 1.0, 1.0},
                                        {0.0, 1.0, r1, r2},
                                        {1.0, 1.0, std::exp(r1), std::exp(r2)},
                                        {0.0, 1.0, r1 * std::exp(r1), r2 * std::exp(r2)}}};
  C det = 1.0;
  for (int c = 0; c < 4; ++c) {  // Gaussian elimination with partial pivoting
    int p = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::abs(a[r][c]) > std::abs(a[p][c])) p = r;
    if (p != c) std::swap(a[p], a[c]), det = -det;
    det *= a[c][c];
    for (int r = c + 1; r < 4; ++r) {
      const C f = a[r][c] / a[c][c];
      for (int k = c; k < 4; ++k) a[r][k] -= f * a[c][k];
    }
  }
  return det;
}

TEST(Greenhill, ZeroTensionIsTwiceFirstTanRoot) {
  // M L / B = 2 x_1; the t = 0 characteristic function is exactly sin u - u cos u, so the root is
  // found to 4 eps.
  EXPECT_NEAR(clamped_twisted_critical_moment(1.0, 0.0, 1.0), 8.98681891581813, 1e-10);
  EXPECT_NEAR(clamped_twisted_critical_moment(2.5, 0.0, 0.7) * 0.7 / 2.5, 8.98681891581813, 1e-10);
  // Continuity through t = 0 (the characteristic function is smooth in t there).
  EXPECT_NEAR(clamped_twisted_critical_moment(1.0, 1e-9, 1.0), 8.98681891581813, 1e-8);
  EXPECT_NEAR(clamped_twisted_critical_moment(1.0, -1e-9, 1.0), 8.98681891581813, 1e-8);
}

TEST(MichellRing, CriticalTwistsAreSqrtNSquaredMinusOne) {
  // C tau R / B = sqrt(n^2 - 1): sqrt(3) for the first pair (Michell's), sqrt(8) and sqrt(15) next.
  EXPECT_DOUBLE_EQ(michell_ring_critical_twist(1.0, 1.0, 1.0), std::sqrt(3.0));
  EXPECT_DOUBLE_EQ(michell_ring_critical_twist(2.0, 0.5, 1.5, 3) * 0.5 * 1.5 / 2.0, std::sqrt(8.0));
  EXPECT_DOUBLE_EQ(michell_ring_critical_twist(1.0, 1.0, 1.0, 4), std::sqrt(15.0));
  EXPECT_THROW(michell_ring_critical_twist(1.0, 1.0, 1.0, 1), std::invalid_argument);  // a rigid turn
  EXPECT_THROW(michell_ring_critical_twist(1.0, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(michell_ring_critical_twist(1.0, 1.0, -1.0), std::invalid_argument);
}

TEST(Greenhill, RootsSolveTheBoundaryDeterminant) {
  const double B = 1.0, L = 1.0;
  for (double t : {-39.0, -20.0, -1.0, 0.5, 5.0, 50.0, 1e3}) {
    SCOPED_TRACE("t = " + std::to_string(t));
    const double m = clamped_twisted_critical_moment(B, t * B / (L * L), L) * L / B;
    // Near a simple root |D(m +- d)| ~ |D'| d, while |D(m)| ~ |D'| * (root error ~ 1e-15 m) plus
    // rounding of the determinant; the ratio is ~1e-12, so 1e-8 leaves a wide margin.
    const double d = 1e-3;
    const double scale = std::max(std::abs(clamped_boundary_determinant(m - d, t)),
                                  std::abs(clamped_boundary_determinant(m + d, t)));
    EXPECT_LT(std::abs(clamped_boundary_determinant(m, t)), 1e-8 * scale);
  }
}

// Greenhill's long-rod value 2 sqrt(B T) is a strict lower bound (energy argument in
// analytic.cpp), and the analysis predicts M ~ 2 sqrt(B T + pi^2 B^2 / L^2), i.e. a relative
// excess ~ pi^2 B / (2 T L^2). The bound below allows twice that.
TEST(Greenhill, LongRodApproachesGreenhillValue) {
  const double B = 1.3, T = 0.7, greenhill = 2.0 * std::sqrt(B * T);
  double previous_excess = INFINITY;
  for (double L : {10.0, 100.0, 1000.0, 1e4}) {
    SCOPED_TRACE("L = " + std::to_string(L));
    const double excess = clamped_twisted_critical_moment(B, T, L) / greenhill - 1.0;
    EXPECT_GT(excess, 0.0);
    EXPECT_LT(excess, kPi * kPi * B / (T * L * L));
    EXPECT_LT(excess, previous_excess);
    previous_excess = excess;
  }
  // The asymptotic form itself. From F = t sin(beta) - 4 beta sin(u1) sin(u2) (analytic.cpp),
  // beta = pi + O(4 pi / t), so its relative error is below 4 pi^2 / t^2 to leading order;
  // allow twice that (t = T L^2 / B = 5.4e3 and 5.4e5: tolerances 2.7e-6 and 2.7e-10).
  for (double L : {100.0, 1000.0}) {
    const double t = T * L * L / B;
    const double asymptotic = 2.0 * std::sqrt(B * T + kPi * kPi * B * B / (L * L));
    EXPECT_NEAR(clamped_twisted_critical_moment(B, T, L), asymptotic, 8.0 * kPi * kPi / (t * t) * asymptotic);
  }
}

// Compression lowers the critical moment, which vanishes at the clamped-clamped Euler load.
TEST(Greenhill, CompressionLowersTheMomentToZeroAtEulerLoad) {
  const double B = 1.0, L = 1.0;
  double previous = 0.0;
  for (double t : {-39.4, -30.0, -10.0, 0.0, 10.0, 100.0}) {
    const double M = clamped_twisted_critical_moment(B, t, L);
    EXPECT_GT(M, previous) << "t = " << t;
    previous = M;
  }
  const double euler = euler_critical_load(EulerEnds::ClampedClamped, B, L);
  EXPECT_LT(clamped_twisted_critical_moment(B, -euler * (1.0 - 1e-8), L), 1e-2);
  EXPECT_THROW(clamped_twisted_critical_moment(B, -euler, L), std::invalid_argument);
}

// --------------------------------------------------------------------------------------------
// Bad inputs

void expect_invalid(const std::function<void()>& call, const std::string& argument) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected std::invalid_argument naming " << argument;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(argument), std::string::npos) << e.what();
  }
}

TEST(Analytic, BadInputsThrow) {
  expect_invalid([] { PinnedElastica{0.0, 1.0, 1.0}.load(); }, "L");
  expect_invalid([] { PinnedElastica{1.0, -1.0, 1.0}.load(); }, "EI");
  expect_invalid([] { PinnedElastica{1.0, 1.0, 0.0}.load(); }, "theta0");
  expect_invalid([] { PinnedElastica{1.0, 1.0, kPi}.k(); }, "theta0");
  expect_invalid([] { PinnedElastica{1.0, 1.0, NAN}.y_max(); }, "theta0");
  expect_invalid([] { PinnedElastica{1.0, 1.0, 1.0}.theta(-0.1); }, "s");
  expect_invalid([] { PinnedElastica{1.0, 1.0, 1.0}.x(1.1); }, "s");
  expect_invalid([] { PinnedElastica{INFINITY, 1.0, 1.0}.y(0.5); }, "L");
  expect_invalid([] { eq54_kappa_max(0.0, 1.0, 1.0); }, "P");
  expect_invalid([] { eq54_y_max(1.0, 0.0, 1.0); }, "EI");
  expect_invalid([] { eq54_y_max(1.0, 1.0, 4.0); }, "theta0");
  expect_invalid([] { euler_critical_load(EulerEnds::PinnedPinned, 1.0, 1.0, 0); }, "mode must be");
  expect_invalid([] { euler_critical_load(EulerEnds::PinnedPinned, 0.0, 1.0); }, "EI");
  expect_invalid([] { euler_critical_load(EulerEnds::ClampedClamped, 1.0, -2.0); }, "L");
  expect_invalid([] { tan_x_equals_x_root(0); }, "n must be");
  expect_invalid([] { StraightTwistedRod{1.0, 0.0, 1.0, 1.0, 0.0}.twisting_moment(); }, "C");
  expect_invalid([] { StraightTwistedRod{1.0, 1.0, 1.0, NAN, 0.0}.hamiltonian(); }, "phi");
  expect_invalid([] { clamped_twisted_critical_moment(0.0, 1.0, 1.0); }, "B");
  expect_invalid([] { clamped_twisted_critical_moment(1.0, 1.0, 0.0); }, "L");
  expect_invalid([] { clamped_twisted_critical_moment(1.0, -50.0, 1.0); }, "T");
  expect_invalid([] { clamped_twisted_critical_moment(1.0, NAN, 1.0); }, "T");
  expect_invalid([] { flat_contact_buckling(1.0, 1.0, 0.0); }, "a");
  expect_invalid([] { flat_contact_buckling(1.0, 1.0, 0.2); }, "a");
  expect_invalid([] { contact_flattening(0.0, 1.0, 0.1); }, "L");
  expect_invalid([] { second_mode_arches(1.0, 0.0, 0.1); }, "EI");
  expect_invalid([] { second_mode_arches(1.0, 1.0, 0.25); }, "a");
}

// A clamped-clamped rod against a wall a -> 0 above its clamps: where the contact flattens the
// two outer arcs are full waves of length L/2 (P -> 4 pi^2 EI / (L/4)^2 = 16 pi^2 EI / L^2); where the
// flat part buckles, arcs and flat part all have length L/3 (P -> 36 pi^2 EI / L^2); the second
// mode touching the wall is the clamped-clamped 16 pi^2 EI / L^2 mode. Corrections are O(a^2).
TEST(Analytic, WallConfigurationsTendToEulerLoadsForALowWall) {
  const double a = 1e-4, pi2 = kPi * kPi;
  EXPECT_NEAR(contact_flattening(1.0, 1.0, a).P / (16.0 * pi2), 1.0, 1e-6);
  EXPECT_NEAR(flat_contact_buckling(1.0, 1.0, a).P / (36.0 * pi2), 1.0, 1e-6);
  EXPECT_NEAR(flat_contact_buckling(1.0, 1.0, a).flat_length, 1.0 / 3.0, 1e-6);
  EXPECT_NEAR(second_mode_arches(1.0, 1.0, a).P / (16.0 * pi2), 1.0, 1e-6);
  // Scaling: lengths with L, loads with EI / L^2.
  const auto base = flat_contact_buckling(1.0, 1.0, 0.1), scaled = flat_contact_buckling(2.0, 3.0, 0.2);
  EXPECT_NEAR(scaled.P, base.P * 3.0 / 4.0, 1e-9 * base.P);
  EXPECT_NEAR(scaled.Delta, 2.0 * base.Delta, 1e-12);
}

}  // namespace
