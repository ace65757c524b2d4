// The simply supported Elastica (Fig. 3) against the elliptic-integral solution and eq. (54).
#include <cmath>

#include "kirchhoff/analysis/analytic.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// Newton stops at |F| <= 1e-10 and RK78 runs at 1e-12 per step, so P is accurate to ~1e-11
// relative; 1e-9 leaves room for the conditioning of P with respect to theta0 near pi.
constexpr double kLoadTolerance = 1e-9;
// y_max and kappa_max come from a Brent refinement of the sampled maximum (location to ~1e-8,
// value error quadratic in it) on top of the same integration error: 1e-8 as the issue asks.
constexpr double kShapeTolerance = 1e-8;

class PinnedElastica : public ::testing::TestWithParam<double> {};

TEST_P(PinnedElastica, MatchesEllipticSolutionAndEq54) {
  const double theta0 = GetParam();
  const analytic::PinnedElastica exact{1.0, 1.0, theta0};
  // A reasonable guess for the unknown load (10% high); far from it, at theta0 near pi, Newton
  // may find another equilibrium with the same slope.
  const auto solved = testing::solve_case("simply_supported.toml", {{"theta0", theta0}, {"P", 1.1 * exact.load()}});
  const auto& d = solved.solution.derived;
  EXPECT_NEAR(d.at("P") / exact.load(), 1.0, kLoadTolerance);
  EXPECT_NEAR(solved.solution.result.parameters["P"] / exact.load(), 1.0, kLoadTolerance);
  const double P = d.at("P");
  EXPECT_NEAR(d.at("y_max"), analytic::eq54_y_max(P, 1.0, theta0), kShapeTolerance);
  EXPECT_NEAR(d.at("kappa_max"), analytic::eq54_kappa_max(P, 1.0, theta0), kShapeTolerance);
  EXPECT_NEAR(d.at("end_to_end"), std::abs(exact.end_to_end()), kShapeTolerance);
  // The whole shape, point by point.
  for (const auto& p : solved.solution.profile) {
    ASSERT_NEAR(p.r.x(), exact.x(p.s), kShapeTolerance) << "s = " << p.s;
    ASSERT_NEAR(p.r.y(), exact.y(p.s), kShapeTolerance) << "s = " << p.s;
  }
  // H flat to round-off (eq. 53), and equal to -P cos(theta0) at the support.
  const auto& H = solved.solution.invariants.H;
  EXPECT_TRUE(H.applies);
  EXPECT_LE(H.relative_spread(), 1e-9);
  EXPECT_NEAR(H.mean, -P * std::cos(theta0), 1e-9 * H.scale);
}

INSTANTIATE_TEST_SUITE_P(Slopes, PinnedElastica, ::testing::Values(0.5, 1.0, 2.0, 2.8));

TEST(EulerColumn, StraightColumnSolvesForEveryLoad) {
  for (double P : {2.0, 12.0, 50.0}) {
    const auto solved = testing::solve_case("euler_column.toml", {{"P", P}, {"theta_guess", 0.0}});
    EXPECT_NEAR(solved.solution.derived.at("theta0"), 0.0, 1e-12);
    EXPECT_NEAR(solved.solution.derived.at("y_max"), 0.0, 1e-12);
  }
}

TEST(EulerColumn, BuckledGuessConvergesToTheBuckledElastica) {
  // Above pi^2 the first buckled mode exists; its end slope solves 4 K(k)^2 = P.
  const double P = 12.0;
  const auto solved = testing::solve_case("euler_column.toml", {{"P", P}, {"theta_guess", 1.0}});
  const double theta0 = solved.solution.derived.at("theta0");
  EXPECT_GT(theta0, 0.5);
  const analytic::PinnedElastica exact{1.0, 1.0, theta0};
  EXPECT_NEAR(exact.load() / P, 1.0, kLoadTolerance);
  EXPECT_NEAR(solved.solution.derived.at("y_max"), exact.y_max(), kShapeTolerance);
}

}  // namespace
}  // namespace kirchhoff

namespace kirchhoff {
namespace {

// A rod of natural curvature 2 pi, both ends pinned at the origin and no force: its unstressed
// circle, theta linear in s. RKF78's error estimate vanishes there (stages 12 and 13 repeat 1 and
// 11 where the right-hand side depends on s alone), and a residual's single march took steps of
// 0.01, 0.05, 0.25 and the rest of the rod: the ring's closure came out 6.7e-5 (a probe; the same
// march with the variational equations, whose errors it sees, 5e-15), and `solve` reported a
// singular Jacobian at residual 6.7e-5 instead of the circle. The planar equations bound the step
// by the turn of theta (IntegratorOptions::max_step). 1e-12: the state's tolerance, on a rod of
// unit length whose closure is a sum of ~20 steps' errors.
TEST(NaturallyCurvedRing, ClosesInOneMarchWithoutForce) {
  const std::string text = testing::kNaturalRingPinnedAtOnePoint;
  const Case c = load_case_text(text, "ring.toml");
  ShootingProblem problem(c.definition);
  const Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  Eigen::VectorXd F;
  std::string failure;
  ASSERT_TRUE(problem.evaluate(x, &F, nullptr, &failure)) << failure;
  EXPECT_LT(F.lpNorm<Eigen::Infinity>(), 1e-12) << F.transpose();
  // Five turns of a tighter ring (k0 = 10 pi): the bound is on the turn, not the length.
  const Case tight = load_case_text(text, "ring5.toml", {{"k0", 10 * M_PI}});
  ShootingProblem five(tight.definition);
  ASSERT_TRUE(five.evaluate(five.initial_unknowns(tight.start_guess), &F, nullptr, &failure)) << failure;
  EXPECT_LT(F.lpNorm<Eigen::Infinity>(), 1e-12) << F.transpose();
}

}  // namespace
}  // namespace kirchhoff
