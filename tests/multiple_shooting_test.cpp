// Multiple shooting gives the same solution as single shooting, and reaches strongly loaded
// rods whose single-shooting sensitivities blow up.
#include "kirchhoff/analysis/analytic.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

ShootingResult solve_with_segments(const char* file, const ParameterOverrides& overrides, int segments) {
  Case c = load_case(testing::case_path(file), overrides);
  c.definition.options.segments = segments;
  const ShootingProblem problem(c.definition);
  return solve(problem, problem.initial_unknowns(c.start_guess));
}

TEST(MultipleShooting, SameLoadAsSingleShooting) {
  for (int segments : {1, 2, 5, 8}) {
    const ShootingResult r = solve_with_segments("simply_supported.toml", {{"theta0", 2.0}}, segments);
    ASSERT_TRUE(r.summary.converged()) << segments << " segments: " << r.summary.brief_report();
    EXPECT_NEAR(r.parameters["P"] / (analytic::PinnedElastica{1.0, 1.0, 2.0}.load()), 1.0, 1e-9) << segments;
  }
}

TEST(MultipleShooting, ThreeDimensionalRod) {
  for (int segments : {1, 3}) {
    Case c = load_case(testing::case_path("twisted_clamped.toml"), {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}},
                       "axial");
    c.definition.options.segments = segments;
    const ShootingProblem problem(c.definition);
    const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
    ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
    const Solution s = make_solution(problem, r, 11, {"M"});
    EXPECT_NEAR(s.derived.at("M"), 8.782876841, 1e-8) << segments;
  }
}

}  // namespace
}  // namespace kirchhoff
