// Frictionless point contact by complementarity in the shooting core (wall.toml), checked
// against the elliptic-function solution and against the symmetric half-rod shooting.
#include <algorithm>
#include <cmath>
#include <fstream>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/discrete_elastica.hpp"
#include "kirchhoff/analysis/point_record.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

struct ContactRun {
  Case c;
  ContactSolveResult solve;
  std::unique_ptr<ShootingProblem> problem;
  Solution solution;
};

ContactRun run(const ParameterOverrides& overrides = {}) {
  ContactRun r;
  r.c = load_case(testing::case_path("wall.toml"), overrides);
  r.solve = solve_with_contacts(r.c.definition, r.c.start_guess);
  r.problem = std::make_unique<ShootingProblem>(r.solve.definition);
  r.solution = make_solution(*r.problem, r.solve.result, 401, r.c.derived);
  return r;
}

TEST(PointContact, WallFoundFromTheFreeArchAgreesWithTheEllipticSolution) {
  const ContactRun r = run();
  ASSERT_TRUE(r.solve.result.summary.converged()) << r.solve.result.summary.brief_report();
  ASSERT_TRUE(r.solve.complementarity) << r.solve.message;
  // One round: the free arch penetrates at mid-span, a contact is added there.
  ASSERT_EQ(r.solve.log.size(), 1u);
  EXPECT_NE(r.solve.log[0].find("add a contact"), std::string::npos);
  ASSERT_EQ(r.solution.contacts.size(), 1u);
  // Shooting (Newton to 1e-12) and Jacobi elliptic functions: ~1e-12 apart; 1e-8 is the bar.
  const auto exact = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1);
  const auto& d = r.solution.derived;
  EXPECT_NEAR(d.at("P") / exact.P, 1.0, 1e-8);
  EXPECT_NEAR(d.at("contact_force") / exact.contact_force, 1.0, 1e-8);
  EXPECT_NEAR(d.at("kappa_contact") / exact.kappa_c, 1.0, 1e-8);
  EXPECT_NEAR(d.at("H") / exact.H, 1.0, 1e-8);
  EXPECT_NEAR(d.at("contact_s"), 0.5, 1e-9);  // symmetry, not imposed
  // Complementarity: never inside the wall, touching where the force acts.
  EXPECT_GE(d.at("min_gap"), -1e-10);
  EXPECT_GT(r.solution.contacts[0].force, 0.0);
  // H is the same on both sides of the contact (section 6.3): flat over the whole rod.
  EXPECT_LE(r.solution.invariants.H.relative_spread(), 1e-9);
  const RodModel& model = r.problem->equations(r.solve.result.parameters)->model();
  const double s_c = r.solution.contacts[0].s;
  const auto sides = r.problem->sample(r.solve.result.x, {s_c - 1e-3, s_c + 1e-3});
  const double before = hamiltonian(model, sides[0]), after = hamiltonian(model, sides[1]);
  EXPECT_NEAR(before, after, 1e-9 * std::abs(before));
  // ... while n_y jumps by the contact force there (eq. 63).
  EXPECT_NEAR(sides[1].n.y() - sides[0].n.y(), r.solution.contacts[0].force, 1e-9 * exact.contact_force);
}

TEST(PointContact, NoContactWhenTheWallIsOutOfReach) {
  const ContactRun r = run({{"a", 0.2}});
  ASSERT_TRUE(r.solve.complementarity);
  EXPECT_TRUE(r.solution.contacts.empty());
  EXPECT_GT(r.solution.derived.at("min_gap"), 0.05);
}

TEST(PointContact, AnEndInsideTheObstacleIsInfeasible) {
  const Case c = load_case(testing::case_path("wall.toml"), {{"a", -0.01}});
  try {
    solve_with_contacts(c.definition, c.start_guess);
    FAIL() << "expected InfeasibleContact";
  } catch (const InfeasibleContact& e) {
    EXPECT_NE(std::string(e.what()).find("inside obstacle 'wall'"), std::string::npos) << e.what();
  }
}

TEST(PointContact, JacobianThroughTheContactEqualsFiniteDifferences) {
  const ContactRun r = run();
  // Away from the solution, as in jacobian_test.cpp (tolerance justified there).
  Eigen::VectorXd x = r.solve.result.x;
  for (int i = 0; i < x.size(); ++i) x[i] += 0.01 * std::sin(1.0 + 2.3 * i);
  Eigen::VectorXd F;
  Eigen::MatrixXd J, J_fd;
  std::string failure;
  ASSERT_TRUE(r.problem->evaluate(x, &F, &J, &failure)) << failure;
  ASSERT_TRUE(finite_difference_jacobian(*r.problem, x, 1e-6, &J_fd));
  EXPECT_LE((J - J_fd).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, J.cwiseAbs().maxCoeff()));
}

// Multiple shooting through the contact: the segments of each piece move with the contact point,
// the jump sits between the pieces. Started from the single-shooting solution's states at its nodes
// (unknowns_from) with the contact 0.01 away and its force 10 % off. Same solution as single shooting to Newton's tolerance (1e-12
// on the residual; the loads are O(10-100), so 1e-9 relative), and its Jacobian - node blocks,
// the contact's arclength moving every node of both pieces - equals finite differences.
TEST(PointContact, MultipleShootingThroughTheContactAgreesWithSingleShooting) {
  const ContactRun single = run();
  ASSERT_TRUE(single.solve.complementarity);
  for (int segments : {2, 5}) {
    ProblemDefinition d = single.solve.definition;
    d.contacts = single.problem->contacts_at(single.solve.result.x);
    d.contacts[0].s += 0.01;  // start elsewhere: the nodes move with it
    d.contacts[0].force *= 0.9;
    d.options.segments = segments;
    const ShootingProblem problem(d);
    ASSERT_EQ(problem.piece_segments().size(), 2u);
    const ShootingResult r =
        solve(problem, problem.unknowns_from(single.problem->sample(single.solve.result.x, problem.node_arclengths())));
    ASSERT_TRUE(r.summary.converged()) << segments << ": " << r.summary.brief_report();
    const Solution s = make_solution(problem, r, 401, single.c.derived);
    EXPECT_NEAR(s.derived.at("P") / single.solution.derived.at("P"), 1.0, 1e-9) << segments;
    EXPECT_NEAR(s.contacts[0].s, single.solution.contacts[0].s, 1e-9) << segments;
    EXPECT_NEAR(s.contacts[0].force / single.solution.contacts[0].force, 1.0, 1e-9) << segments;
    EXPECT_LE(s.invariants.H.relative_spread(), 1e-9);
    Eigen::VectorXd x = r.x;
    for (int i = 0; i < x.size(); ++i) x[i] += 0.01 * std::sin(1.0 + 2.3 * i);
    Eigen::VectorXd F;
    Eigen::MatrixXd J, J_fd;
    std::string failure;
    ASSERT_TRUE(problem.evaluate(x, &F, &J, &failure)) << failure;
    ASSERT_TRUE(finite_difference_jacobian(problem, x, 1e-6, &J_fd));
    EXPECT_LE((J - J_fd).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, J.cwiseAbs().maxCoeff())) << segments;
  }
}

ContactContinuationResult continue_wall(double to) {
  const Case c = load_case(testing::case_path("wall.toml"), {{"Delta", 0.005}, {"m_guess", 0.9}});
  RodContinuationOptions o;
  o.parameter = "Delta";
  o.target = to;
  o.max_step = 2.0;
  o.max_points = 1000;
  o.derived = {"P", "contact_force", "kappa_contact", "H"};
  return continue_with_contacts(c.definition, c.start_guess, o);
}

TEST(ContactContinuation, FromTheFreeArchThroughFirstContact) {
  const ContactContinuationResult r = continue_wall(0.026);
  ASSERT_EQ(r.result.reason, StopReason::ReachedTarget) << r.result.message;
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_NE(r.changes[0].find("a contact appears"), std::string::npos);
  int events = 0;
  for (const auto& p : r.result.points) events += p.type == PointType::Event ? 1 : 0;
  EXPECT_EQ(events, 1);
  // The free clamped-clamped arch first touches at y_max = a; its end shortening is where the
  // event was located (before it no contact, after it one).
  const auto& last = r.result.points.back();
  const auto exact = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1);
  // The corrector stops at |F| <= 1e-10: P to ~1e-10 relative.
  EXPECT_NEAR(last.derived.at("P") / exact.P, 1.0, 1e-8);
  EXPECT_NEAR(last.derived.at("contact_force") / exact.contact_force, 1.0, 1e-8);
  for (const auto& p : r.result.points) EXPECT_TRUE(H_is_flat(p)) << "Delta = " << p.parameter;
}

TEST(ContactContinuation, PointContactFlattensIntoAnExtendedContact) {
  const Case c = load_case(testing::case_path("wall.toml"), {{"Delta", 0.005}, {"m_guess", 0.9}});
  RodContinuationOptions o;
  o.parameter = "Delta";
  o.target = 0.04;
  o.max_step = 2.0;
  o.max_points = 3000;
  o.derived = {"P", "H", "contact_s", "contact_length", "kappa_contact", "min_gap"};
  const ContactContinuationResult r = continue_with_contacts(c.definition, c.start_guess, o);
  ASSERT_EQ(r.result.reason, StopReason::ReachedTarget) << r.result.message;
  ASSERT_EQ(r.changes.size(), 2u);
  EXPECT_NE(r.changes[1].find("flattens into an extended contact"), std::string::npos);
  const auto& at = r.result.points.back();
  // Lying flat on the wall over an interval centred on mid-span. The ends of a flat contact are
  // contacts of higher order (the rod leaves with zero curvature: gap ~ (s - s1)^3), so residuals
  // of 1e-10 locate them only to ~1e-7 (observed 3e-7): checked to 1e-5.
  EXPECT_GT(at.derived.at("contact_length"), 0.1);
  EXPECT_NEAR(at.derived.at("contact_s") + 0.5 * at.derived.at("contact_length"), 0.5, 1e-5);
  EXPECT_GE(at.derived.at("min_gap"), -1e-9);
  // Section 7.2: on the flat part kappa = 0 and theta = 0, so H = -P there, and H is the same
  // everywhere: H = -P to the corrector's tolerance.
  EXPECT_NEAR(at.derived.at("H"), -at.derived.at("P"), 1e-9 * at.derived.at("P"));
  EXPECT_TRUE(H_is_flat(at));
}

// The active-set loop from the free arch at Delta = 0.032 adds a contact at mid-span, then a
// second where the rod still penetrates, and settles on two point contacts with the rod straight
// on the wall between them: the flat contact continuation reaches there by contact_flattens. It is
// reported as that extended contact, with the continuation's load and interval.
TEST(FlatContact, TwoPointContactsWithTheRodFlatBetweenThemAreOneExtendedContact) {
  const ContactRun r = run({{"Delta", 0.032}});
  ASSERT_TRUE(r.solve.result.summary.converged()) << r.solve.result.summary.brief_report();
  ASSERT_TRUE(r.solve.complementarity) << r.solve.message;
  ASSERT_EQ(r.solution.contacts.size(), 1u);
  const PointContact& flat = r.solution.contacts[0];
  EXPECT_TRUE(flat.extended);
  EXPECT_TRUE(std::any_of(r.solve.log.begin(), r.solve.log.end(), [](const std::string& line) {
    return line.find("between them: one extended contact over [") != std::string::npos;
  }));
  // Section 7.2: H = -P on a flat contact.
  EXPECT_NEAR(r.solution.derived.at("H"), -r.solution.derived.at("P"), 1e-9 * r.solution.derived.at("P"));
  // As continuation finds it (its corrector stops at 1e-10: P to ~1e-10 relative; the ends of a
  // flat contact are contacts of higher order, located to ~1e-6 only, see above).
  const Case c = load_case(testing::case_path("wall.toml"));
  RodContinuationOptions o;
  o.parameter = "Delta";
  o.target = 0.032;
  o.max_step = 2.0;
  o.max_points = 3000;
  o.derived = {"P", "contact_s", "contact_length"};
  const ContactContinuationResult branch = continue_with_contacts(c.definition, c.start_guess, o);
  ASSERT_EQ(branch.result.reason, StopReason::ReachedTarget) << branch.result.message;
  const auto& at = branch.result.points.back().derived;
  EXPECT_NEAR(r.solution.derived.at("P") / at.at("P"), 1.0, 1e-8);
  EXPECT_NEAR(flat.s, at.at("contact_s"), 1e-5);
  EXPECT_NEAR(r.solution.derived.at("contact_length"), at.at("contact_length"), 1e-5);
}

// wall.toml at Delta = 0.04 with the flat contact stated at the answer (as continuation finds
// it): the clamps' moment is 0 there (H = -P at a clamp parallel to the wall), a double root on
// which Newton stalls at the integrator's round-off, just above the shipped tolerance 1e-12.
std::string stated_flat_contact_case(const std::string& tolerance) {
  const std::string path = testing::scratch_path("stated_flat_contact_" + tolerance + ".toml");
  std::ofstream out(path);
  out << R"(model = "planar"
[parameters]
Delta = 0.04
[rod]
length = 1.0
B = 1.0
[start]
type = "clamped"
position = [0, 0]
[end]
type = "clamped"
position = ["1 - Delta", 0]
[[obstacles]]
type = "plane"
name = "wall"
point = [0, 0.1]
normal = [0, -1, 0]
[solver]
tolerance = )" << tolerance << R"(
[guess]
force = [-251.69080938464018, -67.8683322754695]
moment = [0, 0, 0]
[[guess.contacts]]
obstacle = "wall"
s = 0.39085166519642295
s_end = 0.6091485362774002
force = 67.8683322754695
force_end = 67.86833227546919
)";
  return path;
}

TEST(FlatContact, StatedAtTheAnswerConvergesAtTheShippedTolerance) {
  const Case c = load_case(stated_flat_contact_case("1e-12"));
  const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_TRUE(r.result.summary.converged()) << r.result.summary.brief_report();
  EXPECT_LE(r.result.summary.residual_norm, 10 * 1e-12);  // at round-off (kRoundOffFactor)
  ASSERT_EQ(r.definition.contacts.size(), 1u);
  EXPECT_TRUE(r.definition.contacts[0].extended);
  // The load continuation gives there (to 1e-10, its corrector's tolerance).
  EXPECT_NEAR(-r.result.x[3] / 251.69080938464018, 1.0, 1e-9);
  // It did not move: nothing said about the stated contact.
  EXPECT_TRUE(r.stated_moves.empty());
}

TEST(FlatContact, StatedButBeyondRoundOffSaysWhy) {
  // A tolerance a hundred times below the integrator's noise: no solve reaches it, and the
  // message says why.
  const Case c = load_case(stated_flat_contact_case("1e-14"));
  const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_FALSE(r.result.summary.converged());
  EXPECT_NE(r.message.find("double root"), std::string::npos) << r.message;
  EXPECT_NE(r.result.summary.message.find("double root"), std::string::npos) << r.result.summary.message;
}

// wrapped_indenter.toml with its wrap stated at the closed form's answer: converged at the case's
// tolerance where it was stated (a wrap around a disc has no flat part: no singular Jacobian).
TEST(StatedContacts, AWrapStatedAtTheAnswerConvergesThere) {
  const auto exact = analytic::three_point_bending_wrapped(1.0, 1.0, 0.5, -35.0 * M_PI / 180.0);
  Case c = load_case(testing::case_path("wrapped_indenter.toml"));
  ASSERT_EQ(c.definition.contacts.size(), 1u);
  PointContact& wrap = c.definition.contacts[0];
  wrap.s = exact.contact_start;
  wrap.s_end = 1.0 - exact.contact_start;
  wrap.force = wrap.force_end = exact.edge_force;
  c.start_guess.n = Vec3(0.0, exact.force / 2.0, 0.0);
  // The case's guess turns the start by 0.6 rad; the answer leaves the pin at +35 degrees.
  c.start_guess.R = Eigen::AngleAxisd(35.0 * M_PI / 180.0 - 0.6, Vec3::UnitZ()).toRotationMatrix() * c.start_guess.R;
  const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_TRUE(r.result.summary.converged()) << r.result.summary.brief_report();
  EXPECT_LE(r.result.summary.iterations, 2);  // started at the answer (to ~1e-11)
  EXPECT_TRUE(r.log.empty());
  EXPECT_TRUE(r.stated_moves.empty()) << r.stated_moves.front();
  EXPECT_NEAR(r.definition.contacts[0].s, exact.contact_start, 1e-9);
}

TEST(StatedContacts, OneThatMovesSaysWhereItWent) {
  // indenter.toml states its contact at s = L/2; with the disc moved sideways the contact slides.
  const Case c = load_case(testing::case_path("indenter.toml"), {{"half_span", 0.40}});
  const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_TRUE(r.result.summary.converged()) << r.result.summary.brief_report();
  EXPECT_TRUE(r.log.empty());  // no change of the active set
  ASSERT_EQ(r.stated_moves.size(), 1u);
  const std::string& line = r.stated_moves.back();
  EXPECT_NE(line.find("stated at s = 0.5 converged at s = "), std::string::npos) << line;
  const auto outcomes = stated_contact_outcomes(c.definition.contacts, r.definition.contacts, c.definition.obstacles, 1.0);
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_TRUE(outcomes[0].moved);
  EXPECT_FALSE(outcomes[0].released);
  EXPECT_NE(outcomes[0].solved.s, 0.5);
  EXPECT_EQ(line, outcomes[0].message);
}

TEST(StatedContacts, KeptMovedAndReleasedAreTold) {
  const std::vector<Obstacle> walls{Obstacle::plane(Vec3(0, 0.1, 0), Vec3(0, -1, 0), "wall")};
  const std::vector<PointContact> stated{{0, 0.2, 1.0}, {0, 0.5, 1.0}};
  PointContact wrap{0, 0.3, 1.0};
  wrap.extended = true;
  wrap.s_end = 0.6;
  // The contact at 0.5 stays (within 1e-6 L); the one at 0.2 finds nothing left: released.
  auto o = stated_contact_outcomes(stated, {{0, 0.5 + 1e-8, 2.0}}, walls, 1.0);
  ASSERT_EQ(o.size(), 2u);
  EXPECT_TRUE(o[0].released);
  EXPECT_NE(o[0].message.find("stated at s = 0.2 is not in the solution"), std::string::npos) << o[0].message;
  EXPECT_FALSE(o[1].moved);
  EXPECT_NE(o[1].message.find("('wall') stated at s = 0.5 stayed there"), std::string::npos) << o[1].message;
  o = stated_contact_outcomes({stated[1]}, {wrap}, walls, 1.0);
  EXPECT_TRUE(o[0].moved);
  EXPECT_NE(o[0].message.find("stated at s = 0.5 converged over [0.3, 0.6]"), std::string::npos) << o[0].message;
}

TEST(FailedSolve, AfterTheNLoptSearchSaysWhatWasTried) {
  // From the free arch at Delta = 0.04 the active-set loop reaches two point contacts that do not
  // converge (the flat contact is reached by continuation; see docs/contact.md).
  const ContactRun r = run({{"Delta", 0.04}});
  ASSERT_FALSE(r.solve.result.summary.converged());
  const std::string& m = r.solve.result.summary.message;
  EXPECT_NE(m.find("tried 2 starts: Newton from the guess"), std::string::npos) << m;
  EXPECT_NE(m.find("NLopt least-squares search"), std::string::npos) << m;
  EXPECT_NE(m.find("best residual"), std::string::npos) << m;
  EXPECT_NE(m.find("2 contact(s)"), std::string::npos) << m;
}

// Further on, the flat part is a strut clamped by the wall at both ends under the compression P:
// it buckles away from the wall when P l^2 = 4 pi^2 EI, and the rod becomes a hanging fold, two
// point contacts with a blister between them.
class HangingFold : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Case c = load_case(testing::case_path("wall.toml"), {{"Delta", 0.005}, {"m_guess", 0.9}});
    RodContinuationOptions o;
    o.parameter = "Delta";
    o.target = 0.07;
    o.max_step = 2.0;
    o.max_points = 6000;
    o.derived = {"P", "H", "contact_length", "kappa_contact", "min_gap", "min_contact_force"};
    branch = new testing::ContactBranch(testing::follow_contacts(c, o));
    for (size_t i = 0; i < branch->points.size(); ++i)
      if (branch->points[i].event.find("hanging fold") != std::string::npos) onset = i;
  }
  static void TearDownTestSuite() { delete branch; }
  // Points on the fold: two point contacts.
  static bool on_fold(size_t i) { return i > onset; }
  static testing::ContactBranch* branch;
  static size_t onset;
};
testing::ContactBranch* HangingFold::branch = nullptr;
size_t HangingFold::onset = 0;

TEST_F(HangingFold, FormsWhereTheFlatPartReachesItsEulerLoad) {
  const auto& r = branch->result;
  ASSERT_EQ(r.result.reason, StopReason::ReachedTarget) << r.result.message;
  ASSERT_EQ(r.changes.size(), 3u);
  EXPECT_NE(r.changes[2].find("buckles away from the obstacle: a hanging fold"), std::string::npos);
  const ContinuationPoint& at = branch->points[onset];
  EXPECT_EQ(at.type, PointType::Event);
  const double l = at.derived.at("contact_length");
  // Located by the secant method on the margin to the corrector's tolerance.
  EXPECT_NEAR(at.derived.at("P") * l * l / (4.0 * M_PI * M_PI), 1.0, 1e-8);
  // Against the elliptic-function onset (no ODE). On the flat branch the Jacobian is singular
  // (see contact.cpp), so a corrector residual of 1e-10 leaves errors ~2e4 times larger: observed
  // 1.2e-6 in Delta, 2.1e-6 in P, 1.0e-6 in l (1.4e-7 in P with a residual of 1e-11).
  const auto exact = analytic::flat_contact_buckling(1.0, 1.0, 0.1);
  EXPECT_NEAR(at.parameter / exact.Delta, 1.0, 5e-6);
  EXPECT_NEAR(at.derived.at("P") / exact.P, 1.0, 5e-6);
  EXPECT_NEAR(l / exact.flat_length, 1.0, 5e-6);
  // Two point contacts where the flat part ended.
  ASSERT_LT(onset + 1, branch->points.size());
  const auto fold = branch->contacts(onset + 1);
  ASSERT_EQ(fold.size(), 2u);
  EXPECT_FALSE(fold[0].extended || fold[1].extended);
  EXPECT_NEAR(fold[0].s, exact.contact_start, 1e-3);
  EXPECT_NEAR(fold[1].s, 1.0 - exact.contact_start, 1e-3);
}

TEST_F(HangingFold, BlisterStartsAsTheStrutsFirstModeAwayFromTheWall) {
  ASSERT_LT(onset + 1, branch->points.size());
  const ContinuationPoint& first = branch->points[onset + 1];
  const ShootingProblem& problem = *branch->problems[onset + 1];
  const auto c = branch->contacts(onset + 1);
  const double l = c[1].s - c[0].s, mid = 0.5 * (c[0].s + c[1].s);
  std::vector<double> s;
  for (int i = 1; i < 20; ++i) s.push_back(c[0].s + l * i / 20.0);
  const auto profile = problem.sample(first.x, s);
  const Obstacle& wall = problem.definition().obstacles[0];
  const double depth = wall.gap(problem.sample(first.x, {mid}).front().r);
  ASSERT_GT(depth, 0.0);  // away from the wall
  // g(s) = depth (1 - cos(2 pi (s - s1) / l)) / 2 up to the nonlinear correction, O(k^2) with
  // k = |kappa_c| / (2 sqrt(P)) ~ 1e-3 at the first point: 1e-3 of the depth is a tight bar.
  for (const auto& p : profile)
    EXPECT_NEAR(wall.gap(p.r) / depth, 0.5 * (1.0 - std::cos(2.0 * M_PI * (p.s - c[0].s) / l)), 1e-3) << p.s;
}

TEST_F(HangingFold, IsSymmetricWithPushingContactsAndOneH) {
  int fold_points = 0;
  for (size_t i = onset + 1; i < branch->points.size(); ++i, ++fold_points) {
    const ContinuationPoint& p = branch->points[i];
    const auto c = branch->contacts(i);
    ASSERT_EQ(c.size(), 2u) << p.parameter;
    EXPECT_NEAR(c[0].s + c[1].s, 1.0, 1e-8) << p.parameter;  // the symmetric fold
    EXPECT_GE(p.derived.at("min_contact_force"), 0.0) << p.parameter;
    EXPECT_GE(p.derived.at("min_gap"), -1e-9) << p.parameter;
    // H is the same everywhere (the profile) and on both sides of each contact.
    EXPECT_LE(invariants_of(p).H.relative_spread(), 1e-9) << p.parameter;
    for (const auto& contact : c) {
      const auto [before, after] = testing::hamiltonian_across(*branch->problems[i], p.x, contact.s);
      EXPECT_NEAR(before, after, 1e-9 * std::abs(before)) << p.parameter;
    }
    // At a contact theta = 0 and n3 = -P: H = EI kappa_c^2 / 2 - P > -P (section 7.2).
    const double kc = p.derived.at("kappa_contact");
    EXPECT_NEAR(p.derived.at("H") + p.derived.at("P"), 0.5 * kc * kc, 1e-9 * p.derived.at("P")) << p.parameter;
  }
  EXPECT_GT(fold_points, 20);
}

TEST_F(HangingFold, IsSubcriticalTurningBackInDelta) {
  // The fold branch leaves the flat one towards smaller Delta (unstable), turns at a fold of the
  // branch and then grows with Delta: the flat contact snaps into the fold at the onset.
  int turns = 0;
  for (size_t i = onset + 1; i < branch->points.size(); ++i)
    if (branch->points[i].type == PointType::Fold) {
      ++turns;
      EXPECT_LT(branch->points[i].parameter, branch->points[onset].parameter);
    }
  EXPECT_EQ(turns, 1);
}

TEST_F(HangingFold, BlisterIsAClampedClampedElastica) {
  // Between the contacts n_y = 0 (symmetry) and theta = 0 at both ends: the first clamped-clamped
  // mode of length l, a pinned half-wave of length l/2 between its inflection points with a
  // quarter-wave on either side. Its contact curvature gives k = |kappa_c| / (2 sqrt(P / EI)), and
  // then the elliptic solution gives P = 16 K(k)^2 EI / l^2 and the depth 4 k / lambda.
  const size_t last = branch->points.size() - 1;
  const ContinuationPoint& p = branch->points[last];
  const auto c = branch->contacts(last);
  const double P = p.derived.at("P"), kc = p.derived.at("kappa_contact"), l = c[1].s - c[0].s;
  const analytic::PinnedElastica half{0.5 * l, 1.0, 2.0 * std::asin(std::abs(kc) / (2.0 * std::sqrt(P)))};
  EXPECT_NEAR(half.load() / P, 1.0, 1e-8);
  EXPECT_NEAR(half.kappa_max(), std::abs(kc), 1e-8 * std::abs(kc));
  const ShootingProblem& problem = *branch->problems[last];
  const double depth = problem.definition().obstacles[0].gap(problem.sample(p.x, {0.5}).front().r);
  EXPECT_NEAR(depth, 2.0 * half.y_max(), 1e-8);
  // Beyond the small-blister limit by now (P l^2 = 4 pi^2 EI (1 + k^2 / 2 + ...)).
  EXPECT_GT(P * l * l / (4.0 * M_PI * M_PI), 1.02);
}

}  // namespace
}  // namespace kirchhoff

namespace kirchhoff {
namespace {

// Ipopt on the discretised energy (midpoint rule, second order) converges to the shooting
// solution at the rate 1/N^2, and its contact multiplier to the contact force.
TEST(DiscreteEnergy, IpoptConvergesToTheShootingSolutionAtSecondOrder) {
  const Case c = load_case(testing::case_path("wall.toml"));
  const ContactSolveResult shooting = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_TRUE(shooting.complementarity);
  const ShootingProblem problem(shooting.definition);
  const Solution exact = make_solution(problem, shooting.result, 101, {"P", "contact_force"});
  const std::vector<Obstacle> wall{Obstacle::plane(Vec3(0, 0.1, 0), Vec3(0, -1, 0), "wall")};
  std::vector<double> error_P, error_F, P;
  for (int N : {50, 100, 200}) {
    const DiscreteElasticaResult d = solve_discrete_clamped_elastica(1.0, 1.0, 0.026, wall, N);
    ASSERT_TRUE(d.converged) << d.status;
    EXPECT_GE(d.min_gap, -1e-12);  // no penetration at the nodes (bounds are not relaxed)
    P.push_back(d.P);
    error_P.push_back(std::abs(d.P - exact.derived.at("P")));
    error_F.push_back(std::abs(d.contact_force - exact.derived.at("contact_force")));
  }
  for (int k = 0; k + 1 < 3; ++k) {
    // Halving h divides the error by 4 (observed 3.96-4.00).
    EXPECT_NEAR(error_P[k] / error_P[k + 1], 4.0, 0.2) << k;
    EXPECT_NEAR(error_F[k] / error_F[k + 1], 4.0, 0.3) << k;
  }
  // Richardson's extrapolation of the two finest removes the h^2 term: ~4e-7 left (the h^4 one).
  const double extrapolated = (4.0 * P[2] - P[1]) / 3.0;
  EXPECT_NEAR(extrapolated / exact.derived.at("P"), 1.0, 1e-6);
}

}  // namespace
}  // namespace kirchhoff
