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

// F(x) = 1e12 (x - 1) + 5e-9: at x = 1 the Newton step (-5e-21) does not move x in double
// precision, so no step length lowers |F| = 5e-9 - the situation of a shooting problem in
// tension, where F's sensitivity grows like exp(sqrt(P) L). A step at round-off with |F| within
// 1e3 x the tolerance is convergence (step_at_round_off), not a failed line search.
class SteepWithAFloor : public NonlinearSystem {
 public:
  int size() const override { return 1; }
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, std::string*) const override {
    *F = Eigen::VectorXd::Constant(1, 1e12 * (x[0] - 1.0) + 5e-9);
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, 1e12);
    return true;
  }
};

TEST(Summary, AStepAtRoundOffWhereNoStepLowersTheResidualIsConvergence) {
  NewtonOptions o;
  o.fallback_search = false;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 1.0);
  const NewtonSummary s = newton_solve(SteepWithAFloor(), x, o);
  EXPECT_EQ(s.status, SolverStatus::Converged) << s.brief_report();
  EXPECT_EQ(s.message, "step at round-off");
  EXPECT_DOUBLE_EQ(s.residual_norm, 5e-9);
  // A floor above 1e3 x the tolerance stays a failure with its best residual.
  o.residual_tolerance = 1e-12;
  x[0] = 1.0;
  const NewtonSummary above = newton_solve(SteepWithAFloor(), x, o);
  EXPECT_EQ(above.status, SolverStatus::LineSearchFailed);
  EXPECT_DOUBLE_EQ(above.residual_norm, 5e-9);
}

// The Euler column turned against its load, in tension at P = 1000: with one shooting segment the
// fields grow by exp(sqrt(P) L) = 5e13 and the Jacobian is singular to the solver; the failure
// says that more segments help, and with 8 the same solve converges (2 iterations).
TEST(Summary, ASingularSingleShootingSaysMoreSegmentsHelp) {
  Case c = load_case(testing::case_path("euler_column.toml"), {{"P", 1000.0}, {"theta_guess", M_PI}});
  const ShootingProblem single(c.definition);
  const ShootingResult failed = solve(single, single.initial_unknowns(c.start_guess));
  ASSERT_FALSE(failed.summary.converged());
  EXPECT_NE(failed.summary.message.find("more segments condition it better"), std::string::npos)
      << failed.summary.message;
  c.definition.options.segments = 8;
  const ShootingProblem multiple(c.definition);
  const ShootingResult solved = solve(multiple, multiple.initial_unknowns(c.start_guess));
  ASSERT_TRUE(solved.summary.converged()) << solved.summary.brief_report();
  EXPECT_EQ(solved.summary.message.find("segments"), std::string::npos);
}

// A heavy standing column in units far from 1 (EI = 1e6, weight 7.8e6 per length, q L^3 / EI =
// 7.8, just below Greenhill's 7.8373): its Jacobian is singular to the solver at a residual of
// 3.5e-9, 4e-16 of its forces. The failure said that more segments help, which they do not; it
// says the units are the cause (the same column with EI = 1 and q = 7.8 solves, stable).
TEST(Summary, ASingularSolveFarFromUnitScaleSaysSo) {
  const std::string text = R"(model = "planar"
[parameters]
EI = 1e6
q = 7.8e6
[rod]
length = 1.0
B = "EI"
gravity = { weight = "q", up = [0, 1, 0] }
[start]
type = "clamped"
position = [0, 0]
orientation = { axis = [0, 0, 1], angle = "pi/2" }
[end]
type = "free"
[guess]
orientation = { axis = [0, 0, 1], angle = "pi/2" }
force = [0, "-q"]
)";
  const Case c = load_case_text(text, "heavy_column.toml");
  const ShootingProblem problem(c.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  if (r.summary.converged()) GTEST_SKIP() << "converged here: no failure to describe";
  EXPECT_NE(r.summary.message.find("far from unit scale"), std::string::npos) << r.summary.message;
  EXPECT_EQ(r.summary.message.find("more segments"), std::string::npos) << r.summary.message;
  const Case unit = load_case_text(text, "heavy_column.toml", {{"EI", 1.0}, {"q", 7.8}});
  const ShootingProblem scaled(unit.definition);
  EXPECT_TRUE(solve(scaled, scaled.initial_unknowns(unit.start_guess)).summary.converged());
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

// A toy system F = (x0^2 - 2, eps (x1 - x0)) (condition number ~ 1 / eps) whose step matrices
// are the exact J times `scale`, and which counts the calls of each entry point.
class ScaledStepMatrices final : public NonlinearSystem {
 public:
  explicit ScaledStepMatrices(double scale, double eps = 1.0) : scale_(scale), eps_(eps) {}
  int size() const override { return 2; }
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, std::string*) const override {
    *F = Eigen::Vector2d(x[0] * x[0] - 2.0, eps_ * (x[1] - x[0]));
    if (J) {
      ++exact_matrices;
      *J = matrix(x);
    }
    return true;
  }
  bool has_step_matrices(double) const override { return true; }
  bool evaluate_for_step(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, double,
                         std::string* failure) const override {
    ++step_matrices;
    const bool ok = evaluate(x, F, nullptr, failure);
    if (J) *J = scale_ * matrix(x);
    return ok;
  }
  mutable int exact_matrices = 0, step_matrices = 0;

 private:
  Eigen::MatrixXd matrix(const Eigen::VectorXd& x) const {
    return (Eigen::Matrix2d() << 2.0 * x[0], 0.0, -eps_, eps_).finished();
  }
  double scale_, eps_;
};

TEST(StepMatrices, AGoodOneIsUsedThroughout) {
  // Within 1e-3 of the exact matrix, every full step more than halves |F|: no exact matrix.
  const ScaledStepMatrices system(1.0 + 1e-3);
  Eigen::VectorXd x = Eigen::Vector2d(1.0, 0.0);
  NewtonOptions o;
  o.fallback_search = false;
  const NewtonSummary s = newton_solve(system, x, o);
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-10);
  EXPECT_GT(system.step_matrices, 0);
  EXPECT_EQ(system.exact_matrices, 0);
}

TEST(StepMatrices, AnIllConditionedOneGivesWayToTheExactMatrix) {
  // Condition number ~ 1e8: a step matrix to 1e-8 would converge at a linear rate ~ 1.
  const ScaledStepMatrices system(1.0 + 1e-8, 1e-8);
  Eigen::VectorXd x = Eigen::Vector2d(1.0, 0.0);
  NewtonOptions o;
  o.fallback_search = false;
  o.residual_tolerance = 1e-14;  // on the scale of the second residual, eps
  const NewtonSummary s = newton_solve(system, x, o);
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-10);
  EXPECT_EQ(system.step_matrices, 1);  // the first, refused on its condition number
  EXPECT_GT(system.exact_matrices, 0);
  // A well-conditioned one is kept.
  const ScaledStepMatrices well(1.0 + 1e-8, 1.0);
  x = Eigen::Vector2d(1.0, 0.0);
  ASSERT_TRUE(newton_solve(well, x, o).converged());
  EXPECT_EQ(well.exact_matrices, 0);
}

TEST(StepMatrices, ASingularOneIsRetriedOnTheExactMatrix) {
  const ScaledStepMatrices system(0.0);
  Eigen::VectorXd x = Eigen::Vector2d(1.0, 0.0);
  NewtonOptions o;
  o.fallback_search = false;
  const NewtonSummary s = newton_solve(system, x, o);
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_EQ(system.step_matrices, 1);
  EXPECT_GT(system.exact_matrices, 0);
}

TEST(StepMatrices, ToleranceZeroCallsOnlyEvaluate) {
  const ScaledStepMatrices system(0.0);
  Eigen::VectorXd x = Eigen::Vector2d(1.0, 0.0);
  NewtonOptions o;
  o.fallback_search = false;
  o.step_matrix_tolerance = 0.0;
  ASSERT_TRUE(newton_solve(system, x, o).converged());
  EXPECT_EQ(system.step_matrices, 0);
  o.step_matrix_tolerance = -1.0;
  EXPECT_FALSE(o.validate().empty());
}

// The shooting problem's step matrices: F bit-identical to the residual alone, J the variational
// one to about the step tolerance, every right-hand side counted on the problem.
TEST(StepMatrices, ShootingKeepsTheResidualAndCountsTheWork) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.8}});
  // (Marched: the Elastica's closed-form flow is exact at any tolerance, with no looser pass to test.)
  c.definition.options.integrator.closed_form = false;
  const ShootingProblem problem(c.definition);
  const double tol = c.definition.options.newton.step_matrix_tolerance;
  ASSERT_TRUE(problem.has_step_matrices(tol));
  const Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  Eigen::VectorXd F_alone, F_step, F_exact;
  Eigen::MatrixXd J_step, J_exact;
  std::string failure;
  ASSERT_TRUE(problem.evaluate(x, &F_alone, nullptr, &failure));
  ASSERT_TRUE(problem.evaluate(x, &F_exact, &J_exact, &failure));
  const long before = problem.rhs_evaluations();
  ASSERT_TRUE(problem.evaluate_for_step(x, &F_step, &J_step, tol, &failure));
  const long step_rhs = problem.rhs_evaluations() - before;
  EXPECT_EQ(F_step, F_alone);  // the same integration, bit for bit
  // RK78 at 1e-8 per step: the matrix to ~1e-8 relative, its growth along an Elastica of order
  // one; 1e-6 leaves a hundredfold margin and would catch a matrix at the wrong tolerance.
  EXPECT_LE((J_step - J_exact).lpNorm<Eigen::Infinity>(), 1e-6 * J_exact.lpNorm<Eigen::Infinity>());
  EXPECT_GT((J_step - J_exact).lpNorm<Eigen::Infinity>(), 0.0);  // really another integration
  // Two passes counted: the state's (as F alone) and the variational equations'.
  const long before_alone = problem.rhs_evaluations();
  ASSERT_TRUE(problem.evaluate(x, &F_alone, nullptr, &failure));
  EXPECT_GT(step_rhs, problem.rhs_evaluations() - before_alone);
}

// A step or coarse matrix alone (for a caller that has F): the variational equations' pass
// without the state's own, so exactly the right-hand sides F + J costs less those of F alone, and
// the matrix evaluate_for_step (evaluate_coarse) gives to its tolerance - the end conditions' rows
// now read the looser pass's end state, which moves them by about that tolerance. On the planar
// Elastica (written-out variations, whose pass once left the flow's state unset) and a buckled
// spatial rod.
TEST(StepMatrices, AMatrixAloneSkipsTheStatesPass) {
  struct Setup {
    const char* file;
    ParameterOverrides set;
  };
  for (const Setup& setup : {Setup{"simply_supported.toml", {{"theta0", 2.8}}},
                             Setup{"twisted_clamped.toml", {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}}}}) {
    SCOPED_TRACE(setup.file);
    Case c = load_case(testing::case_path(setup.file), setup.set);
    const ShootingProblem problem(c.definition);
    const double tol = c.definition.options.newton.step_matrix_tolerance;
    const double coarse_tol = c.definition.options.newton.coarse_tolerance;
    ASSERT_TRUE(problem.has_step_matrices(tol));
    ASSERT_TRUE(problem.has_coarse_evaluations(coarse_tol));
    const Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
    Eigen::VectorXd F;
    Eigen::MatrixXd J_step, J_alone, J_coarse, J_coarse_alone;
    std::string failure;
    auto rhs_of = [&](auto&& evaluation) {
      const long before = problem.rhs_evaluations();
      EXPECT_TRUE(evaluation());
      return problem.rhs_evaluations() - before;
    };
    const long f_rhs = rhs_of([&] { return problem.evaluate(x, &F, nullptr, &failure); });
    const long step_rhs = rhs_of([&] { return problem.evaluate_for_step(x, &F, &J_step, tol, &failure); });
    const long alone_rhs = rhs_of([&] { return problem.step_matrix(x, &J_alone, tol, &failure); });
    EXPECT_EQ(alone_rhs, step_rhs - f_rhs);
    // 10 x the tolerance: both matrices are within about it of the exact one.
    EXPECT_LE((J_alone - J_step).lpNorm<Eigen::Infinity>(), 10 * tol * J_step.lpNorm<Eigen::Infinity>());
    const long coarse_f_rhs =
        rhs_of([&] { return problem.evaluate_coarse(x, &F, nullptr, coarse_tol, &failure); });
    const long coarse_rhs = rhs_of([&] { return problem.evaluate_coarse(x, &F, &J_coarse, coarse_tol, &failure); });
    const long coarse_alone_rhs = rhs_of([&] { return problem.coarse_matrix(x, &J_coarse_alone, coarse_tol, &failure); });
    EXPECT_EQ(coarse_alone_rhs, coarse_rhs - coarse_f_rhs);
    // The coarse matrices at 10 x coarse_tol (evaluate_coarse's), the same margin.
    EXPECT_LE((J_coarse_alone - J_coarse).lpNorm<Eigen::Infinity>(),
              100 * coarse_tol * J_coarse.lpNorm<Eigen::Infinity>());
  }
}

TEST(StepMatrices, NotOfferedWithObstaclesOrLooserOwnMatrices) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 1.0}});
  const double tol = 1e-8;
  ProblemDefinition with_wall = c.definition;
  with_wall.obstacles.push_back(Obstacle::plane(Vec3(0.0, -10.0, 0.0), Vec3::UnitY()));
  EXPECT_FALSE(ShootingProblem(with_wall).has_step_matrices(tol));
  ProblemDefinition loose = c.definition;
  loose.options.integrator.sensitivity_tol = 1e-8;
  EXPECT_FALSE(ShootingProblem(loose).has_step_matrices(tol));
  ProblemDefinition coarse = c.definition;
  coarse.options.integrator.abs_tol = 1e-8;
  EXPECT_FALSE(ShootingProblem(coarse).has_step_matrices(tol));
  EXPECT_TRUE(ShootingProblem(c.definition).has_step_matrices(tol));
  // Without step matrices evaluate_for_step is evaluate: the same F and J.
  const ShootingProblem problem(with_wall);
  const Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  Eigen::VectorXd F1, F2;
  Eigen::MatrixXd J1, J2;
  std::string failure;
  ASSERT_TRUE(problem.evaluate(x, &F1, &J1, &failure));
  ASSERT_TRUE(problem.evaluate_for_step(x, &F2, &J2, tol, &failure));
  EXPECT_EQ(F1, F2);
  EXPECT_EQ(J1, J2);
}

// How far apart two points with max |F| <= the tolerance can be near the solution x:
// |dx| <= |J^-1| 2 tol (infinity norms).
double solutions_can_differ_by(const ShootingProblem& problem, const Eigen::VectorXd& x, const NewtonOptions& o) {
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  if (!problem.evaluate(x, &F, &J, &failure)) return 0.0;  // (fails the comparison)
  return J.inverse().cwiseAbs().rowwise().sum().maxCoeff() * 2.0 * o.residual_tolerance;
}

// Newton on the step matrices against Newton on the exact ones, for the Elastica far from its
// solution (theta0 = 2.8 from the case's guess: 8 steps, damped ones among them): the same
// iterations, and solutions as close as two points with |F| <= tol can be: |dx| <= |J^-1| 2 tol.
TEST(StepMatrices, SameNewtonIterationsAndSolutionForTheElastica) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.8}});
  // (Marched: the Elastica's closed-form flow is exact at any tolerance, with no looser pass to test.)
  c.definition.options.integrator.closed_form = false;
  const ShootingProblem problem(c.definition);
  NewtonOptions exact = c.definition.options.newton;
  exact.coarse_tolerance = 0.0;  // the step matrices alone (the coarse phase: CoarsePhase below)
  NewtonOptions step = exact;
  exact.step_matrix_tolerance = 0.0;
  ASSERT_GT(step.step_matrix_tolerance, 0.0);
  const Eigen::VectorXd x0 = problem.initial_unknowns(c.start_guess);
  Eigen::VectorXd x_exact = x0, x_step = x0;
  long rhs = problem.rhs_evaluations();
  const NewtonSummary s_exact = newton_solve(problem, x_exact, exact);
  const long rhs_exact = problem.rhs_evaluations() - rhs;
  rhs = problem.rhs_evaluations();
  const NewtonSummary s_step = newton_solve(problem, x_step, step);
  const long rhs_step = problem.rhs_evaluations() - rhs;
  ASSERT_TRUE(s_exact.converged()) << s_exact.brief_report();
  ASSERT_TRUE(s_step.converged()) << s_step.brief_report();
  EXPECT_EQ(s_step.iterations, s_exact.iterations);
  EXPECT_LT(s_step.evaluations, s_exact.evaluations);  // accepted full steps carry their matrices
  EXPECT_LT(rhs_step, rhs_exact);
  EXPECT_LE((x_step - x_exact).lpNorm<Eigen::Infinity>(), solutions_can_differ_by(problem, x_exact, exact));
}

// A toy system F = (x0^2 - 2, x1 - x0) whose coarse evaluations are off by `error` in each
// component (as an integration to a loose tolerance is), or fail, and which counts its calls.
class CoarseToy final : public NonlinearSystem {
 public:
  explicit CoarseToy(double error, bool coarse_fails = false) : error_(error), fails_(coarse_fails) {}
  int size() const override { return 2; }
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, std::string*) const override {
    ++exact;
    *F = Eigen::Vector2d(x[0] * x[0] - 2.0, x[1] - x[0]);
    if (J) *J = (Eigen::Matrix2d() << 2.0 * x[0], 0.0, -1.0, 1.0).finished();
    return true;
  }
  bool has_coarse_evaluations(double) const override { return true; }
  bool evaluate_coarse(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, double,
                       std::string* failure) const override {
    ++coarse;
    if (fails_) {
      *failure = "coarse integration failed";
      return false;
    }
    const bool ok = evaluate(x, F, J, failure);
    --exact;
    *F += Eigen::Vector2d::Constant(error_);
    return ok;
  }
  mutable int exact = 0, coarse = 0;

 private:
  double error_;
  bool fails_;
};

// Far from the root the iterations are coarse; the solve ends on exact residuals at the exact root
// (the coarse F's root is 1e-7 away: a solve that stopped on coarse residuals would miss
// sqrt(2) by that much, far beyond the 1e-10 asked).
TEST(CoarsePhase, FarIterationsCoarseTheEndExact) {
  NewtonOptions o;
  o.fallback_search = false;
  ASSERT_GT(o.coarse_tolerance, 0.0);
  const CoarseToy system(1e2 * o.coarse_tolerance);
  Eigen::VectorXd x = Eigen::Vector2d(20.0, 0.0);
  const NewtonSummary s = newton_solve(system, x, o);
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-10);
  EXPECT_NEAR(x[1], std::sqrt(2.0), 1e-10);
  EXPECT_GE(system.coarse, 4);  // 20 -> sqrt(2) halves x0 at each of the first few steps
  EXPECT_GT(system.exact, 0);
  // Every coarse |F| above the phase's end (1e4 tolerances = 1e-3) but the last coarse one.
  int coarse_norms = 0;
  for (const double norm : s.history) coarse_norms += norm > 1e4 * o.coarse_tolerance;
  EXPECT_GE(coarse_norms, 3);
}

TEST(CoarsePhase, AFailedCoarseEvaluationIsMadeExactly) {
  NewtonOptions o;
  o.fallback_search = false;
  const CoarseToy system(0.0, true);
  Eigen::VectorXd x = Eigen::Vector2d(20.0, 0.0);
  const NewtonSummary s = newton_solve(system, x, o);
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-10);
  EXPECT_EQ(system.coarse, 1);  // tried once, then the phase is over
}

TEST(CoarsePhase, ToleranceZeroCallsOnlyEvaluate) {
  NewtonOptions o;
  o.fallback_search = false;
  o.coarse_tolerance = 0.0;
  const CoarseToy system(0.0);
  Eigen::VectorXd x = Eigen::Vector2d(20.0, 0.0);
  ASSERT_TRUE(newton_solve(system, x, o).converged());
  EXPECT_EQ(system.coarse, 0);
  o.coarse_tolerance = -1e-7;
  EXPECT_FALSE(o.validate().empty());
  o.coarse_tolerance = 1e-3;  // coarser than any |F| the phase would end at
  EXPECT_FALSE(o.validate().empty());
}

TEST(CoarsePhase, NotOfferedWithObstaclesOrALooserOwnTolerance) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 1.0}});
  const double tol = 1e-7;
  EXPECT_TRUE(ShootingProblem(c.definition).has_coarse_evaluations(tol));
  ProblemDefinition with_wall = c.definition;
  with_wall.obstacles.push_back(Obstacle::plane(Vec3(0.0, -10.0, 0.0), Vec3::UnitY()));
  EXPECT_FALSE(ShootingProblem(with_wall).has_coarse_evaluations(tol));
  ProblemDefinition loose = c.definition;
  loose.options.integrator.abs_tol = 1e-6;
  EXPECT_FALSE(ShootingProblem(loose).has_coarse_evaluations(tol));
}

// The Elastica far from its solution (theta0 = 2.8 from the case's guess, 8 Newton steps): with
// the coarse phase and without, the same solution to what two points with |F| <= tol can differ
// by, |dx| <= |J^-1| 2 tol, for fewer right-hand sides (measured: two thirds; a coarse phase that
// did not engage would make them equal).
TEST(CoarsePhase, SameElasticaForFewerRightHandSides) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.8}});
  // (Marched: the Elastica's closed-form flow is exact at any tolerance, with no looser pass to test.)
  c.definition.options.integrator.closed_form = false;
  const ShootingProblem problem(c.definition);
  NewtonOptions coarse = c.definition.options.newton, exact = coarse;
  exact.coarse_tolerance = 0.0;
  ASSERT_GT(coarse.coarse_tolerance, 0.0);
  const Eigen::VectorXd x0 = problem.initial_unknowns(c.start_guess);
  Eigen::VectorXd x_exact = x0, x_coarse = x0;
  long rhs = problem.rhs_evaluations();
  ASSERT_TRUE(newton_solve(problem, x_exact, exact).converged());
  const long rhs_exact = problem.rhs_evaluations() - rhs;
  rhs = problem.rhs_evaluations();
  const NewtonSummary s = newton_solve(problem, x_coarse, coarse);
  const long rhs_coarse = problem.rhs_evaluations() - rhs;
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_LT(rhs_coarse, 0.8 * rhs_exact);
  EXPECT_LE((x_coarse - x_exact).lpNorm<Eigen::Infinity>(), solutions_can_differ_by(problem, x_exact, exact));
  // The converged residual is the exact one.
  Eigen::VectorXd F;
  std::string failure;
  ASSERT_TRUE(problem.evaluate(x_coarse, &F, nullptr, &failure));
  EXPECT_LE(F.lpNorm<Eigen::Infinity>(), coarse.residual_tolerance);
}

}  // namespace
}  // namespace kirchhoff
