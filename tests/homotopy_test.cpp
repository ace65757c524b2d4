// Solving at --set values by homotopy from the case's own (case_solve.hpp, homotopy.hpp): the
// equilibrium reached is the one on the branch the case's guess starts, checked against closed
// forms; a fold on the way is reported with where it is, and parameters that only shape the guess
// stay guesses.
#include <cmath>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// Newton polishes the path's end at exactly the requested values to |F| <= 1e-10 with RK78 at
// 1e-12 per step, as the direct solves of elastica_test: P to ~1e-11 relative. 1e-9 leaves room
// for the conditioning of P in theta0 near pi (dP/dtheta0 ~ 3e3 at 3.1).
constexpr double kLoadTolerance = 1e-9;

CaseSolve solve_at(const std::string& name, const ParameterOverrides& overrides, bool direct = false) {
  const Case c = load_case(testing::case_path(name), overrides);
  CaseSolveOptions options;
  options.direct = direct;
  return solve_case(c, options);
}

double solved_load(const CaseSolve& s) { return s.solved.result.parameters["P"]; }

class SimplySupportedHomotopy : public ::testing::TestWithParam<double> {};

// Fig. 3's branch up to theta0 = 3.1, past the branch point where the supports meet (2.2814),
// against P = 4 K(k)^2 EI / L^2: Newton from the case's guess lands elsewhere from 2.5 on.
TEST_P(SimplySupportedHomotopy, ReachesFig3sElasticaWhereNewtonFromTheGuessDoesNot) {
  const double theta0 = GetParam();
  const double exact = analytic::PinnedElastica{1.0, 1.0, theta0}.load();
  const CaseSolve s = solve_at("simply_supported.toml", {{"theta0", theta0}});
  ASSERT_TRUE(s.failure.empty()) << s.failure << ": " << s.message;
  ASSERT_TRUE(s.solved.result.summary.converged()) << s.solved.result.summary.brief_report();
  EXPECT_EQ(s.path.method, "homotopy");
  EXPECT_EQ(s.path.homotopy.stop, "reached");
  EXPECT_NEAR(solved_load(s) / exact, 1.0, kLoadTolerance);
  // The solution is at exactly the requested value (polished there, not at the path's t ~ 1).
  EXPECT_EQ(s.solved.result.parameters["theta0"], theta0);
  // The supports meet at theta0 = 2.2814 (end_to_end = 0): the path crosses that branch point.
  ASSERT_EQ(s.path.homotopy.branch_points.size(), 1u);
  const double at = s.path.changes[0].at(s.path.homotopy.branch_points[0]);
  // Located by the determinant's sign change to the continuation's tolerance (~1e-4 here).
  EXPECT_NEAR(at, 2.2814, 2e-3);
  // The direct solve from the same guess reaches another equilibrium (what the homotopy avoids).
  const CaseSolve direct = solve_at("simply_supported.toml", {{"theta0", theta0}}, true);
  EXPECT_EQ(direct.path.method, "direct");
  if (direct.solved.result.summary.converged())
    EXPECT_GT(std::abs(solved_load(direct) / exact - 1.0), 1e-3) << "theta0 = " << theta0;
}

INSTANTIATE_TEST_SUITE_P(Fig3, SimplySupportedHomotopy, ::testing::Values(2.5, 2.95, 3.1));

// Two parameters at once: theta0 and L together, P = 4 K^2 EI / L^2 at the new length.
TEST(Homotopy, MovesEveryChangedParameterTogether) {
  const CaseSolve s = solve_at("simply_supported.toml", {{"theta0", 2.0}, {"L", 2.0}, {"EI", 3.0}});
  ASSERT_TRUE(s.failure.empty()) << s.message;
  ASSERT_TRUE(s.solved.result.summary.converged());
  ASSERT_EQ(s.path.changes.size(), 3u);
  const analytic::PinnedElastica exact{2.0, 3.0, 2.0};  // L, EI, theta0
  EXPECT_NEAR(solved_load(s) / exact.load(), 1.0, kLoadTolerance);
}

// EI down 69 times and L up 3 times at once: P falls from 11.2 to 0.0169, and a step of 1.03 whose
// corrector moved the point 0.21 from its prediction (the steps before: at most 0.024 of theirs)
// landed on the third mode lying beside the first (P = 0.15218 = 9 times, index 2), with no fold or
// branch point to report (a probe's sweep, one row in 70). Such a step is now taken again, shorter.
TEST(Homotopy, DoesNotJumpToAModeLyingBesideItsOwn) {
  const CaseSolve s = solve_at("simply_supported.toml", {{"EI", 0.014491376746189442}, {"theta0", 0.7}, {"L", 3.0}});
  ASSERT_TRUE(s.failure.empty()) << s.message;
  ASSERT_TRUE(s.solved.result.summary.converged());
  const analytic::PinnedElastica exact{3.0, 0.014491376746189442, 0.7};  // L, EI, theta0
  EXPECT_NEAR(solved_load(s) / exact.load(), 1.0, kLoadTolerance);
  ASSERT_TRUE(s.stability && s.stability->index);
  EXPECT_EQ(*s.stability->index, 0);
}

// Values far above the file's (EI = 1e4 from 1, P = 3e4 from 12, L = 2 from 1): the force moves by
// 3e4 along the path, which took more than the 5000 points allowed in steps of the start's size
// (stopped at a third of the way). The steps now grow with the unknowns (measured 62 points).
// The straight column at P L^2 / EI = 12 lies between pi^2 and 4 pi^2: index 1, and its path
// crosses the branch point where P L^2 / EI passes pi^2 again.
TEST(Homotopy, ReachesValuesFarAboveTheFilesInTensOfPoints) {
  const CaseSolve s = solve_at("euler_column.toml", {{"EI", 1e4}, {"L", 2.0}, {"P", 3e4}, {"theta_guess", 0.5}});
  ASSERT_TRUE(s.failure.empty()) << s.failure << ": " << s.message;
  EXPECT_EQ(s.path.homotopy.stop, "reached");
  EXPECT_LT(s.path.homotopy.points, 500);
  ASSERT_TRUE(s.stability && s.stability->index);
  EXPECT_EQ(*s.stability->index, 1);
  const auto& derived = s.solution->derived;
  EXPECT_NEAR(derived.at("end_to_end"), 2.0, 1e-9);  // straight
}

// The shallow arch under its weight snaps through at a fold: asked for a weight beyond it, the
// homotopy stops there and says where, instead of returning an equilibrium of another branch.
TEST(Homotopy, StopsAtAFoldAndSaysWhere) {
  const CaseSolve s = solve_at("shallow_arch.toml", {{"w", 150.0}});
  EXPECT_EQ(s.failure, "fold");
  EXPECT_EQ(s.solved.problem, nullptr);
  EXPECT_NE(s.message.find("fold at w = "), std::string::npos) << s.message;
  const double w_fold = s.path.changes[0].at(s.path.homotopy.fraction);
  // The same fold located independently, by continuation in w itself (another parametrisation
  // of the same branch, so other steps and another located point): both locate dw/dsigma = 0
  // by the secant method to ~1e-8 of the step; 1e-6 relative is far below the fold's value.
  const Case c = load_case(testing::case_path("shallow_arch.toml"));
  RodContinuationOptions o;
  o.parameter = "w";
  o.target = 150.0;
  o.stop_at_fold = true;
  ShootingProblem problem(c.definition);
  const ContinuationResult run = RodContinuation(problem, o).run(problem.initial_unknowns(c.start_guess));
  ASSERT_EQ(run.reason, StopReason::FoldStop);
  EXPECT_NEAR(w_fold / run.points.back().parameter, 1.0, 1e-6);
  // Below the fold the same request is reached.
  const CaseSolve below = solve_at("shallow_arch.toml", {{"w", 0.9 * w_fold}});
  EXPECT_TRUE(below.failure.empty()) << below.message;
}

// A ring of natural curvature 2 pi pinned at one point is one of a family (it turns about its
// pin): the homotopy in its curvature cannot leave it, and stopped at "a fold at k0 = 6.28
// (homotopy fraction -1.6e-13) before reaching the requested values" (a probe). It says that the
// case's own solution is singular, as on a family, and what to do.
TEST(Homotopy, AStartOnAContinuousFamilySaysSo) {
  const CaseSolve s = solve_case(load_case_text(testing::kNaturalRingPinnedAtOnePoint, "ring.toml", {{"k0", 5.0}}));
  ASSERT_FALSE(s.converged());
  if (s.failure != "fold") GTEST_SKIP() << "not stopped as a fold here: " << s.failure << ": " << s.message;
  EXPECT_NE(s.message.find("cannot leave the case's solution"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("continuous family"), std::string::npos) << s.message;
}

// The Euler column's first mode followed from the file's P = 12 to 1000 on one shooting segment:
// past P ~ 520 the fields grow like exp(sqrt(P) L) ~ 1e10 and the corrector's best residual sits
// above the tolerance 1e-10, down to the minimum step. The failure says that more segments help,
// and with 8 the request P = 500 reaches the Elastica: theta0 = 3.14148108804982883,
// the root of 4 K(sin(theta0/2))^2 = 500 (EI = L = 1; bisection in mpmath at 50 digits). Within
// 1e-9: near pi theta0 is ill-conditioned by about 10 against the residual's 1e-10 (with 8, 16
// and 32 segments it comes out 4.7e-10, 2.7e-10 and 1.9e-10 below; P = 4 K^2 from it is 1e-6 off,
// as dP/dtheta0 ~ 1e6 there).
TEST(Homotopy, AStepTooSmallOnOneSegmentSaysMoreSegmentsHelp) {
  // (P = 500 itself is reached on one segment since the path's steps grow with its unknowns: it
  // passes the ill-conditioned stretch in fewer, longer steps; residual 9.4e-11.)
  const CaseSolve one = solve_at("euler_column.toml", {{"P", 1000.0}});
  EXPECT_EQ(one.failure, "step_too_small");
  EXPECT_NE(one.message.find("more segments condition it better"), std::string::npos) << one.message;
  const Case c = load_case(testing::case_path("euler_column.toml"), {{"P", 500.0}}, "", {{"segments", "8"}});
  const CaseSolve eight = solve_case(c);
  ASSERT_TRUE(eight.converged()) << eight.message;
  EXPECT_NEAR(eight.solution->derived.at("theta0"), 3.14148108804982883, 1e-9);
}

// theta_guess shapes only the [guess]: setting it picks the start (the straight column), and the
// load's change is then followed along the straight column, through the Euler load pi^2.
TEST(Homotopy, ParametersOfTheGuessAloneStayGuesses) {
  const Case c = load_case(testing::case_path("euler_column.toml"), {{"theta_guess", 0.0}, {"P", 5.0}});
  EXPECT_FALSE(c.problem_parameters.count("theta_guess"));
  EXPECT_TRUE(c.problem_parameters.count("P"));
  const auto changes = homotopy_changes(c);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].name, "P");
  const CaseSolve s = solve_case(c);
  ASSERT_TRUE(s.failure.empty()) << s.message;
  const Solution sol = make_solution(*s.solved.problem, s.solved.result, 101, c.derived);
  EXPECT_NEAR(sol.derived.at("theta0"), 0.0, 1e-9);
  ASSERT_EQ(s.path.homotopy.branch_points.size(), 1u);
  // On the straight column the determinant is smooth in P and the secant method locates its sign
  // change to ~1e-12 of the step (measured: 2e-12 relative); 1e-8 leaves room for other machines.
  EXPECT_NEAR(s.path.changes[0].at(s.path.homotopy.branch_points[0]) / (M_PI * M_PI), 1.0, 1e-8);
}

// Only guesses changed (the unknown load's): nothing to follow, Newton from the guess.
TEST(Homotopy, OnlyGuessesChangedSolvesDirectly) {
  const CaseSolve s = solve_at("simply_supported.toml", {{"P", 11.0}});
  EXPECT_EQ(s.path.method, "direct");
  EXPECT_TRUE(s.solved.result.summary.converged());
}

// With obstacles the path goes through changes of the contact set: a smaller end shortening
// lowers the arch below the wall, and its contact lifts off on the way.
TEST(Homotopy, FollowsContactSetChanges) {
  const CaseSolve s = solve_at("wall.toml", {{"Delta", 0.02}});
  ASSERT_TRUE(s.failure.empty()) << s.message;
  ASSERT_TRUE(s.solved.result.summary.converged());
  ASSERT_FALSE(s.path.homotopy.contact_changes.empty());
  EXPECT_NE(s.path.homotopy.contact_changes[0].find("Delta = "), std::string::npos)
      << s.path.homotopy.contact_changes[0];
  EXPECT_NE(s.path.homotopy.contact_changes[0].find("lifts off"), std::string::npos);
  EXPECT_TRUE(s.solved.problem->definition().contacts.empty());
}

// On the wall's flat contact (clamps parallel to the wall) the Jacobian is singular and Newton
// stalls at the integrator's noise: at Delta = 0.032 the homotopy's polish ended at 1.05e-12
// against the tolerance 1e-12, and solve reported line_search_failed where a direct solve on the
// same active set accepts such a stall (within 10 x the tolerance) as converged at round-off. The
// polish accepts it the same way and says so; P equals the continuation's at Delta = 0.032
// (`continue cases/wall.toml --param Delta --to 0.032 --set Delta=0.005 --set m_guess=0.9
// --max-step 2`: 167.46928372372) to its 1e-10 relative conditioning (dP/dDelta ~ 3e4).
TEST(Homotopy, PolishOnAFlatContactAcceptsTheStallAtRoundOff) {
  const CaseSolve s = solve_at("wall.toml", {{"Delta", 0.032}});
  ASSERT_TRUE(s.failure.empty()) << s.message;
  ASSERT_TRUE(s.solved.result.summary.converged()) << s.solved.result.summary.brief_report();
  ASSERT_TRUE(s.solution);
  EXPECT_NEAR(s.solution->derived.at("P"), 167.46928372372, 1e-10 * 167.47);
  bool noted = false;
  for (const auto& line : s.path.homotopy.contact_changes)
    noted = noted || line.find("converged at round-off") != std::string::npos;
  EXPECT_TRUE(noted);
}

// The heavy cantilever at w = 300 by homotopy from w = 3: the path ends converged, and Newton's
// polish there starts with a coarse residual 7e-3 off (the coarse phase's integration of so heavy
// a rod), leaves the coarse phase on its ill-conditioned matrix and finds the start converged
// (7e-12). It reported the coarse residual, "converged, residual 0.00707": the residual reported
// is now the one judged, equal to F recomputed at the solution.
TEST(Homotopy, ReportsTheResidualItJudgedNotTheCoarseOne) {
  const CaseSolve s = solve_at("heavy_cantilever.toml", {{"w", 300.0}});
  ASSERT_TRUE(s.failure.empty()) << s.message;
  const NewtonSummary& summary = s.solved.result.summary;
  ASSERT_TRUE(summary.converged()) << summary.brief_report();
  Eigen::VectorXd F;
  std::string failure;
  ASSERT_TRUE(s.solved.problem->evaluate(s.solved.result.x, &F, nullptr, &failure)) << failure;
  EXPECT_LE(summary.residual_norm, s.solved.problem->definition().options.newton.residual_tolerance);
  EXPECT_DOUBLE_EQ(summary.residual_norm, F.lpNorm<Eigen::Infinity>());
}

// The ribbon pressed on its pole, turned from phi = 2 to 4.1: the contact's lift-off (phi =
// 4.165) lies beyond the target inside the path's last step. The path reached its target; it
// ended "stopped (event) at fraction 1" (exit 1) before. The contact holds with force 0.0605, which
// falls to zero at the lift-off (`continue ... --param phi`).
TEST(Homotopy, ReachesATargetWithAContactEventJustBeyondIt) {
  const CaseSolve s = solve_at("twisted_ribbon_pole.toml", {{"phi", 4.1}});
  ASSERT_TRUE(s.failure.empty()) << s.message;
  ASSERT_TRUE(s.solved.result.summary.converged()) << s.solved.result.summary.brief_report();
  EXPECT_EQ(s.path.homotopy.stop, "reached");
  ASSERT_TRUE(s.solution);
  EXPECT_GT(s.solution->derived.at("contact_force"), 0.0);
}

// A clamp turned by a parameter through half a turn: its frame's quaternion passes w = 0 there,
// where a turn angle gauged into (-pi, pi] jumps by 2 pi, and Newton cannot carry the start clamp
// across (the plectoneme case stalled at turns = 0.999 on its way to 1). A straight rod, its start
// clamped turned by alpha about e3, its end sliding along e3 turned by 0, whole turns counted: the
// clamp turned continuously from 0 to alpha twists the rod by -alpha, m3 = -C alpha / L exactly.
constexpr const char* kTurnedClamp = R"(
model = "spatial"
[parameters]
alpha = 0.0
C = 0.769230769230769
[rod]
length = 1.0
B = 1.0
B3 = "C"
[start]
type = "clamped"
position = [0, 0, 0]
orientation = { axis = [0, 0, 1], angle = "alpha" }
[end]
type = "sliding"
axis = [0, 0, 1]
position = [0, 0, 0]
force = [0, 0, 0]
orientation = { axis = [0, 0, 1], angle = 0 }
track_turns = true
[guess]
force = [0, 0, 0]
moment = [0, 0, 0]
[output]
derived = ["M"]
)";

class TurnedClampHomotopy : public ::testing::TestWithParam<double> {};

// Landing exactly on half a turn (pi, where w = 0), and past it (4, 2 pi: a whole turn).
TEST_P(TurnedClampHomotopy, CarriesAClampThroughHalfATurn) {
  const double alpha = GetParam();
  const Case c = load_case_text(kTurnedClamp, "turned_clamp.toml", {{"alpha", alpha}});
  const CaseSolve s = solve_case(c);
  ASSERT_TRUE(s.failure.empty()) << s.failure << ": " << s.message;
  EXPECT_EQ(s.path.homotopy.stop, "reached");
  const Solution sol = make_solution(*s.solved.problem, s.solved.result, 11, c.derived);
  // The straight twisted rod is exact in the equations; Newton's |F| <= 1e-10 and RK78 at 1e-12
  // leave m3 to ~1e-11 (its size is ~1-5).
  EXPECT_NEAR(sol.derived.at("M"), -0.769230769230769 * alpha, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(HalfTurn, TurnedClampHomotopy, ::testing::Values(M_PI, 4.0, 2.0 * M_PI));

}  // namespace
}  // namespace kirchhoff
