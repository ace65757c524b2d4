// The link check (link.hpp): Tw + Wr of the rod closed by its axis equals the imposed end
// rotation along whole branches (Calugareanu-White, an identity the solver does not use), and a
// solve that lands a whole turn away is not called converged.
#include <gtest/gtest.h>

#include <cmath>

#include "kirchhoff/shooting/link.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// The straight twisted rod: Tw = phi / 2 pi exactly (u3 = phi / L), Wr = 0 (a straight line on
// the axis). The bar: trapezoidal u3 of a constant is exact; round-off only.
TEST(Link, StraightTwistedRodIsItsTwist) {
  for (double phi : {0.5, 6.0, 20.0}) {
    const auto solved = testing::solve_case("twisted_clamped.toml", {{"phi", phi}});
    const LinkCheck check = check_link(*solved.problem, solved.solution.result.x);
    ASSERT_TRUE(check.applies) << check.why_not;
    EXPECT_NEAR(check.imposed, phi / (2 * M_PI), 1e-12);
    EXPECT_NEAR(check.twist, phi / (2 * M_PI), 1e-9);
    EXPECT_NEAR(check.writhe, 0.0, 1e-9);
  }
}

// Along the plectoneme branch from the planar Elastica (Lk = 0) through the out-of-plane
// buckling, the end loop and the ply to 4 turns, Tw + Wr of the whole rod (the half and its
// half-turn image) follows the end rotation. Twist turns into writhe as the ply grows (Wr > 1
// by 4 turns), so this checks the writhe integral, the rays and the image. Bar 2e-3 turns: the
// midpoint rule's error at the resolution the check settles at (estimates agree to 1e-3).
TEST(Link, FollowsTheTurnsAlongThePlectonemeBranch) {
  Case c = load_case(testing::case_path("plectoneme.toml"));
  ShootingProblem problem(c.definition);
  const ShootingResult start = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(start.summary.converged());
  RodContinuationOptions o = testing::plectoneme_turns_options(4.0, {});
  o.compute_invariants = false;
  const ContinuationResult branch = RodContinuation(problem, o).run(start.x);
  ASSERT_EQ(branch.reason, StopReason::ReachedTarget) << branch.message;
  double largest_writhe = 0.0;
  int samples = 0;
  for (size_t i = 0; i < branch.points.size(); i += std::max<size_t>(1, branch.points.size() / 12)) {
    const ContinuationPoint& p = branch.points[i];
    problem.set_parameter("turns", p.parameter);
    const LinkCheck check = check_link(problem, p.x);
    ASSERT_TRUE(check.applies) << check.why_not;
    EXPECT_NEAR(check.imposed, p.parameter, 1e-12);
    EXPECT_NEAR(check.link, p.parameter, 2e-3) << "turns " << p.parameter << ": Tw " << check.twist << " Wr "
                                               << check.writhe;
    largest_writhe = std::max(largest_writhe, check.writhe);
    samples = std::max(samples, check.samples);
  }
  EXPECT_GT(largest_writhe, 1.0);
  RecordProperty("largest_samples", samples);
}

// At turns = 2 the case's planar guess already satisfies the end frames (a rotation by 4 pi is
// the identity): Newton returned it after 0 iterations as "converged". Its link is 0, not 2.
TEST(Link, SolveAWholeTurnAwayIsNotConverged) {
  for (double turns : {2.0, 4.0}) {
    const Case c = load_case(testing::case_path("plectoneme.toml"), {{"turns", turns}});
    const DefinitionSolve solved = solve_definition(c.definition, c.start_guess);
    EXPECT_FALSE(solved.result.summary.converged()) << turns << ": " << solved.result.summary.brief_report();
    if (solved.result.summary.status == SolverStatus::CheckFailed)
      EXPECT_NE(solved.result.summary.message.find("whole turns"), std::string::npos) << solved.result.summary.message;
  }
  // Where the guess is close enough to reach the right rod, it converges and its link agrees.
  const Case c = load_case(testing::case_path("plectoneme.toml"), {{"turns", 0.3}});
  const DefinitionSolve solved = solve_definition(c.definition, c.start_guess);
  ASSERT_TRUE(solved.result.summary.converged()) << solved.result.summary.brief_report();
  EXPECT_NEAR(check_link(*solved.problem, solved.result.x).link, 0.3, 2e-3);
}

TEST(Link, SaysWhyItDoesNotApply) {
  const auto planar = testing::solve_case("simply_supported.toml");
  EXPECT_FALSE(check_link(*planar.problem, planar.solution.result.x).applies);
  const auto reissner = testing::solve_case("reissner.toml");
  const LinkCheck check = check_link(*reissner.problem, reissner.solution.result.x);
  EXPECT_FALSE(check.applies);
  EXPECT_FALSE(check.why_not.empty());
}

}  // namespace
}  // namespace kirchhoff
