// Damped Newton, its summary, and the NLopt fallback search for a starting point.
#include "kirchhoff/shooting/newton.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// A guess from which Newton fails within its iteration budget (far from the solution: theta0 =
// 2.8 from P = 0.5 needs 8 Newton steps; two are allowed): the NLopt least-squares search brings
// it close enough for Newton to finish.
TEST(Fallback, NLoptSearchFindsAStartWhereNewtonFails) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.8}, {"P", 0.5}});
  const ShootingProblem problem(c.definition);
  NewtonOptions options = c.definition.options.newton;
  options.max_iterations = 2;
  NewtonOptions plain = options;
  plain.fallback_search = false;
  Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  const NewtonSummary without = newton_solve(problem, x, plain);
  ASSERT_FALSE(without.converged());
  x = problem.initial_unknowns(c.start_guess);
  const NewtonSummary with = solve_with_fallback(problem, x, options);
  ASSERT_TRUE(with.converged()) << with.brief_report();
  EXPECT_TRUE(with.used_fallback_search);
  EXPECT_NE(with.brief_report().find("NLopt"), std::string::npos);
  // The returned point really solves the problem.
  Eigen::VectorXd F;
  std::string failure;
  ASSERT_TRUE(problem.evaluate(x, &F, nullptr, &failure));
  EXPECT_LE(F.lpNorm<Eigen::Infinity>(), options.residual_tolerance);
}

TEST(Summary, ReportsIterationsHistoryAndStatusWords) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 1.0}});
  const ShootingProblem problem(c.definition);
  Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  const NewtonSummary s = newton_solve(problem, x, c.definition.options.newton);
  ASSERT_TRUE(s.converged());
  EXPECT_EQ(static_cast<int>(s.history.size()), s.iterations);
  EXPECT_LE(s.residual_norm, 1e-10);
  // Quadratic convergence: each residual at most about the square of the previous (relative to 1).
  for (size_t k = 1; k < s.history.size(); ++k)
    if (s.history[k - 1] < 1e-2) EXPECT_LE(s.history[k], 10.0 * s.history[k - 1] * s.history[k - 1] + 1e-12);
  EXPECT_STREQ(to_string(SolverStatus::SingularJacobian), "singular_jacobian");
  EXPECT_STREQ(to_string(SolverStatus::MaxIterations), "max_iterations");
}

TEST(Summary, MaxIterationsIsReportedWithTheBestResidual) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.0}, {"P", 12.0}});
  const ShootingProblem problem(c.definition);
  NewtonOptions o = c.definition.options.newton;
  o.max_iterations = 1;
  o.fallback_search = false;
  Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  const NewtonSummary s = newton_solve(problem, x, o);
  EXPECT_EQ(s.status, SolverStatus::MaxIterations);
  EXPECT_GT(s.residual_norm, o.residual_tolerance);
  EXPECT_TRUE(std::isfinite(s.residual_norm));
}

}  // namespace
}  // namespace kirchhoff
