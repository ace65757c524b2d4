// The planar rod's closed-form flow (equations/detail/elastica_flow.hpp) against GSL's elliptic
// functions and against the march it replaces, and the march itself in the direction of
// decreasing s.
#include <gsl/gsl_sf_elljac.h>
#include <gsl/gsl_sf_ellint.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kirchhoff/equations/detail/elastica_flow.hpp"
#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {
namespace {

// GSL computes sn, cn, dn by the same mean and E(phi | k) by Carlson's integrals: agreement to
// a few ulps of the values' size (1e-14) on u up to four quarter periods, m from 0 to 1 - 1e-6.
TEST(JacobiElliptic, AgreesWithGsl) {
  for (double m : {0.0, 1e-14, 1e-6, 0.3, 0.7, 0.99, 1 - 1e-6}) {
    for (double u : {-3.1, -0.2, 0.0, 0.4, 1.3, 2.9, 7.5}) {
      const detail::JacobiValues<double> j = detail::jacobi_elliptic(u, m, 1.0 - m);
      double sn, cn, dn;
      ASSERT_EQ(gsl_sf_elljac_e(u, m, &sn, &cn, &dn), 0);
      EXPECT_NEAR(j.sn, sn, 1e-14) << "m " << m << " u " << u;
      EXPECT_NEAR(j.cn, cn, 1e-14) << "m " << m << " u " << u;
      EXPECT_NEAR(j.dn, dn, 1e-14) << "m " << m << " u " << u;
      // int_0^u sn^2 = (u - E(am u | m)) / m where am u is within a quarter period (|u| < K).
      // (Formed from GSL's E, the difference loses digits to cancellation as m falls: 1e-15 u / m,
      // so only m >= 0.3 is compared, to 1e-14 u; small m is ZeroParameterIsTrigonometric's.)
      if (m >= 0.3 && std::abs(u) < gsl_sf_ellint_Kcomp(std::sqrt(m), GSL_PREC_DOUBLE)) {
        const double am = std::atan2(sn, cn);
        const double expected = (u - gsl_sf_ellint_E(am, std::sqrt(m), GSL_PREC_DOUBLE)) / m;
        EXPECT_NEAR(j.epsilon_minus_u_over_m, expected, 1e-14 * (1 + std::abs(u))) << "m " << m << " u " << u;
      }
    }
  }
}

// At m = 0 the functions are sin, cos and 1, and int sn^2 = (u - sin u cos u) / 2, exactly.
TEST(JacobiElliptic, ZeroParameterIsTrigonometric) {
  const detail::JacobiValues<double> j = detail::jacobi_elliptic(0.9, 0.0, 1.0);
  EXPECT_DOUBLE_EQ(j.sn, std::sin(0.9));
  EXPECT_DOUBLE_EQ(j.cn, std::cos(0.9));
  EXPECT_DOUBLE_EQ(j.dn, 1.0);
  EXPECT_NEAR(j.epsilon_minus_u_over_m, 0.5 * (0.9 - std::sin(0.9) * std::cos(0.9)), 1e-15);
}

struct RandomRod {
  RodModel model;
  Eigen::VectorXd y0 = Eigen::VectorXd(6);
  double ds = 0.0;
};

RandomRod random_rod(std::mt19937& g, int t) {
  std::uniform_real_distribution<double> U(-1, 1);
  RandomRod r;
  const double B = std::exp(2 * U(g));
  r.model.B = {Profile(B), Profile(B), Profile(B)};
  r.model.u_hat[1] = Profile(t % 3 == 0 ? 0.0 : 2 * U(g));
  if (t % 5 == 0) {  // a natural shear and stretch: r' = v1 d1 + v3 d3
    r.model.v_hat[0] = Profile(0.3 * U(g));
    r.model.v_hat[2] = Profile(1 + 0.3 * U(g));
  }
  // Forces from 1e-3 to 1e2 (so phases lambda ds from below the closed form's least to 20).
  const double scale = std::pow(10.0, -3 + 5 * std::abs(U(g)));
  r.y0 << U(g), U(g), 3 * U(g), scale * U(g), scale * U(g), 0.7 * std::sqrt(scale) * U(g);
  if (t % 7 == 0) r.y0[3] = 1e-6 * U(g);  // a force nearly along one axis
  r.ds = t % 11 == 0 ? -2 * std::abs(U(g)) : 3 * std::abs(U(g));  // backwards too
  return r;
}

// The closed form against the march at 1e-13 (RKF78 on the same equations, Phi from its
// variational equations): random rods and states, natural curvature, shear, stretch, flows
// backwards. Within the closed form's limits (elastica_flow.hpp) the two agree to 2e-13 in the
// state and 1.6e-11 in Phi where 1 - m > 1e-2 (relative to their norms); nearer the separatrix,
// where the orbit's sensitivity grows like 1 / (1 - m), to 1e-11 in the state (as far as the
// march at 1e-12 is from the one at 1e-14 there) and 1.4e-10 in Phi. The bars are 1e-11 and
// 3e-10 of the norms. Of 2,000 states, those whose orbit oscillates over a
// long enough phase take the closed form; the others (turning over, short phases) march.
TEST(ElasticaFlow, AgreesWithTheMarch) {
  std::mt19937 g(7);
  int closed = 0;
  for (int t = 0; t < 2000; ++t) {
    const RandomRod r = random_rod(g, t);
    const auto eq = make_planar_equations(r.model);
    IntegratorOptions march;
    march.closed_form = false;
    march.abs_tol = march.rel_tol = 1e-13;
    IntegratorOptions exact;
    const SegmentFlow a = eq->flow(r.y0, 0.0, r.ds, true, exact);
    if (a.rhs_evaluations > 0) continue;  // marched: not in the oscillating regime
    ++closed;
    const SegmentFlow b = eq->flow(r.y0, 0.0, r.ds, true, march);
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(a.y[i], b.y[i], 1e-11 * (1 + b.y.norm())) << "state " << t << " row " << i;
      for (int j = 0; j < 6; ++j)
        EXPECT_NEAR(a.Phi(i, j), b.Phi(i, j), 3e-10 * (1 + b.Phi.norm())) << "state " << t;
    }
    const SegmentFlow alone = eq->flow(r.y0, 0.0, r.ds, false, exact);
    EXPECT_EQ((alone.y - a.y).norm(), 0.0);  // F is the same number with or without Phi
  }
  EXPECT_GT(closed, 300);
  EXPECT_LT(closed, 2000);  // (the turning-over states march)
}

// Love's kinetic analogue in a case that is known: the Euler column's first mode, clamped at
// s = 0 and free at L = 1, its tip angle alpha under P with sqrt(P) = K(sin(alpha / 2)), the
// complete integral of the first kind. The flow from the clamp must end moment-free.
TEST(ElasticaFlow, TheEulerColumnEndsMomentFree) {
  for (double alpha : {0.1, 1.0, 2.0, 2.8, 3.1, 3.13}) {
    const double k = std::sin(alpha / 2);
    const double P = std::pow(gsl_sf_ellint_Kcomp(k, GSL_PREC_DOUBLE), 2);
    // The moment at the clamp (theta = 0) by H: B theta'^2 / 2 = P (cos theta - cos alpha).
    const double m0 = std::sqrt(2 * P * (1 - std::cos(alpha)));
    Eigen::VectorXd y0(6);
    y0 << 0, 0, 0, -P, 0, m0;
    const auto eq = make_planar_equations(RodModel{});
    const SegmentFlow f = eq->flow(y0, 0.0, 1.0, false, IntegratorOptions{});
    // (At 3.13, 1 - m = cos^2(1.565) = 3.4e-5: the state is closed form to 1 - m = 1e-4, and this
    // one is marched, to the march's accuracy there: the orbit's sensitivity is 1 / (1 - m).)
    if (alpha < 3.12) ASSERT_EQ(f.rhs_evaluations, 0) << alpha;
    const double bar = alpha < 3.12 ? 1e-12 : 1e-8;
    EXPECT_NEAR(f.y[5], 0.0, bar * P) << alpha;
    EXPECT_NEAR(f.y[2], alpha, bar) << alpha;
  }
}

// Outside the oscillating regime the rod is marched: no force (a ring), a rod that turns over.
TEST(ElasticaFlow, TurningOverOrUnloadedRodsAreMarched) {
  const auto eq = make_planar_equations(RodModel{});
  Eigen::VectorXd ring(6), over(6);
  ring << 0, 0, 0, 0, 0, 2 * M_PI;
  over << 0, 0, 0, -1, 0, 3.0;  // theta'^2 = 9 > 4 P: past the separatrix
  EXPECT_GT(eq->flow(ring, 0.0, 1.0, true, IntegratorOptions{}).rhs_evaluations, 0);
  EXPECT_GT(eq->flow(over, 0.0, 1.0, true, IntegratorOptions{}).rhs_evaluations, 0);
  RodModel extensible;  // (a pendulum no longer: the force stretches the rod)
  extensible.extensible = true;
  extensible.A = {Profile(100.0), Profile(100.0), Profile(100.0)};
  Eigen::VectorXd bent(6);
  bent << 0, 0, 0.3, -5, 0, 0.1;
  EXPECT_GT(make_planar_equations(extensible)->flow(bent, 0.0, 1.0, false, IntegratorOptions{}).rhs_evaluations, 0);
}

// A profile in closed form is the flow's own end, sample by sample.
// A profile's samples (ShootingProblem::sample) start with the segment's start repeated, and may
// hold intervals shorter than the closed form's least phase. Neither may send the profile to the
// march: composed interval by interval, the closed form agrees with its one-interval flow to
// round-off (measured 1.4e-15 here), where the march agrees to its tolerance (2.6e-13).
TEST(ElasticaFlow, SamplesAreTheFlowsStates) {
  const auto eq = make_planar_equations(RodModel{});
  Eigen::VectorXd y0(6);
  y0 << 0, 0, 0.2, -12, 1, 3;
  const std::vector<double> s{0.0, 0.0, 0.25, 0.5, 0.5 + 1e-12, 1.0};
  const std::vector<Eigen::VectorXd> states = eq->sample(y0, s, IntegratorOptions{});
  const SegmentFlow whole = eq->flow(y0, 0.0, 1.0, false, IntegratorOptions{});
  ASSERT_EQ(states.size(), s.size());
  EXPECT_EQ(states[1], y0);
  EXPECT_LT((states.back() - whole.y).norm(), 2e-15 * whole.y.norm());
  IntegratorOptions march;
  march.closed_form = false;
  const std::vector<Eigen::VectorXd> marched = eq->sample(y0, s, march);
  for (size_t i = 0; i < s.size(); ++i) EXPECT_LT((states[i] - marched[i]).norm(), 1e-10 * (1 + marched[i].norm()));
}

// A profile's equal intervals share their Jacobi functions (JacobiMemo): along an orbit m is
// invariant and v = lambda ds the same, so of 100 intervals one forms them (m drifts by round-off
// from state to state, within the memo's bound away from the separatrix; at 1 - m = 1.2e-4 it
// drifts further and most intervals form their own: 93 measured). The states agree with flows
// that each form their own to 1e-13 of a state of size 20 (measured 1.4e-13 at theta0 = 2.9, where
// both differ from the one-interval flow by 1e-13 and 5e-14). A change of orbit recomputes.
TEST(ElasticaFlow, EqualIntervalsShareTheirJacobiFunctions) {
  const detail::ElasticaConstants rod;
  for (const double theta0 : {0.3, 2.9, 3.12}) {  // 1 - m from 0.98 to 1.2e-4 (the state's limit: 1e-4)
    std::array<double, 6> y{0, 0, theta0, -20, 0, 0}, alone = y, next{};
    detail::JacobiMemo memo;
    const double ds = 0.01;
    for (int i = 0; i < 100; ++i) {
      ASSERT_TRUE(detail::elastica_flow(y.data(), ds, rod, next.data(), detail::kStateLimits, &memo));
      y = next;
      ASSERT_TRUE(detail::elastica_flow(alone.data(), ds, rod, next.data(), detail::kStateLimits));
      alone = next;
    }
    if (theta0 < 3) EXPECT_EQ(memo.evaluations, 1) << "theta0 " << theta0;
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(y[k], alone[k], 1e-13 * 20) << "theta0 " << theta0 << " k " << k;
    std::array<double, 6> other{0, 0, theta0, -30, 0, 0};
    const int before = memo.evaluations;
    ASSERT_TRUE(detail::elastica_flow(other.data(), ds, rod, next.data(), detail::kStateLimits, &memo));
    EXPECT_EQ(memo.evaluations, before + 1);
  }
}

// Near the separatrix, off an equilibrium (a Newton iterate), the flow over a long phase: the
// addition theorems' denominator 1 - S0^2 sn^2 is formed as D0^2 + S0^2 cn^2, without the
// cancellation to 1 - m that cost 1.7e-9 and 5.4e-9 of these states (size 20 to 50). Against a
// march at 1e-15 (which agrees with one at 1e-12 to 4e-11 here): measured 7e-12 to 6e-11.
TEST(ElasticaFlow, LongPhasesNearTheSeparatrixKeepTheirDigits) {
  const auto eq = make_planar_equations(RodModel{});
  IntegratorOptions tight;
  tight.closed_form = false;
  tight.abs_tol = tight.rel_tol = 1e-15;
  for (const double theta0 : {3.1, 3.12})
    for (const double P : {20.0, 50.0}) {
      Eigen::VectorXd y0(6);
      y0 << 0, 0, theta0, -P, 0, 0;
      const SegmentFlow closed = eq->flow(y0, 0.0, 1.0, false, IntegratorOptions{});
      ASSERT_EQ(closed.rhs_evaluations, 0);
      const SegmentFlow marched = eq->flow(y0, 0.0, 1.0, false, tight);
      EXPECT_LT((closed.y - marched.y).norm(), 3e-10) << "theta0 " << theta0 << " P " << P;
    }
}

// The march towards smaller s under a step bound (a naturally curved ring: the planar equations
// bound the step there). odeint's own bound turned such a step round, towards larger s, until
// the step count ran out; the march must end where the forward march started.
TEST(March, RunsBackwardsUnderAStepBound) {
  RodModel ring;
  ring.u_hat[1] = Profile(2 * M_PI);
  const auto eq = make_planar_equations(ring);
  Eigen::VectorXd y0(6);
  y0 << 0.1, 0.2, 0.3, 0, 0, 0;
  const SegmentFlow there = eq->flow(y0, 0.0, 0.7, false, IntegratorOptions{});
  const SegmentFlow back = eq->flow(there.y, 0.7, 0.0, false, IntegratorOptions{});
  EXPECT_LT((back.y - y0).norm(), 1e-12);
  EXPECT_LT(back.steps, 100);
}

}  // namespace
}  // namespace kirchhoff
