// Curved obstacles: cylinders (discs in the plane) and level sets, by complementarity in the
// shooting core, checked against the closed form of three-point bending (elliptic integrals),
// against global equilibrium about the disc's centre, against the same shapes written as level
// sets, and against Ipopt's discrete Elastica.
#include <cmath>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/discrete_elastica.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

constexpr double kSupportSlope = -35.0 * M_PI / 180.0;  // indenter.toml's defaults

// --- the obstacles' own geometry ------------------------------------------------------------

TEST(Obstacle, CylinderGradientAndHessianAreTheDerivativesOfItsGap) {
  const Obstacle disc = Obstacle::cylinder(Vec3(0.3, -0.2, 0.0), Vec3(0, 0, 2), 0.1);
  const Vec3 r(0.42, -0.05, 0.7);  // off the disc's plane: the axis direction does not count
  const double h = 1e-5;
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = Vec3::Unit(i);
    // Central differences: error ~h^2 |g'''| ~ 1e-10 here.
    EXPECT_NEAR(disc.gradient(r)[i], (disc.gap(r + h * e) - disc.gap(r - h * e)) / (2 * h), 1e-8);
    const Vec3 column = (disc.gradient(r + h * e) - disc.gradient(r - h * e)) / (2 * h);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(disc.hessian(r)(j, i), column[j], 1e-7);
  }
  EXPECT_NEAR(disc.gap(Vec3(0.3, -0.1, 5.0)), 0.0, 1e-15);
  EXPECT_NEAR(disc.normal(r).norm(), 1.0, 1e-15);
  EXPECT_NEAR(disc.normal(r).z(), 0.0, 1e-15);
}

TEST(Obstacle, LevelSetDerivativesAreFourthOrderAccurate) {
  const Obstacle disc = Obstacle::cylinder(Vec3(0.3, -0.2, 0.0), Vec3::UnitZ(), 0.1);
  const auto g = [](const Vec3& r) { return std::hypot(r.x() - 0.3, r.y() + 0.2) - 0.1; };
  const Vec3 r(0.42, -0.05, 0.0);
  // Step 1e-3 at distance 0.19 from the centre: h^4 g^(5) ~ 1e-12 * 24 / 0.19^4 ~ 2e-8 at most.
  const Obstacle coarse = Obstacle::level_set(g, "disc", "", 1e-3);
  EXPECT_LE((coarse.gradient(r) - disc.gradient(r)).norm(), 1e-8);
  EXPECT_LE((coarse.hessian(r) - disc.hessian(r)).norm(), 1e-6);
  // Ten times smaller: 1e4 times more accurate until round-off (1e-16 / h) takes over.
  const Obstacle fine = Obstacle::level_set(g, "disc", "", 1e-4);
  EXPECT_LE((fine.gradient(r) - disc.gradient(r)).norm(), 1e-11);
  // The reaction's direction turns with the contact point as d nu / dr.
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = Vec3::Unit(i);
    const Vec3 column = (disc.normal(r + h * e) - disc.normal(r - h * e)) / (2 * h);
    EXPECT_LE((disc.normal_derivative(r).col(i) - column).norm(), 1e-8);
  }
}

TEST(Obstacle, RefusesDegenerateShapes) {
  EXPECT_THROW(Obstacle::cylinder(Vec3::Zero(), Vec3::UnitZ(), 0.0), std::invalid_argument);
  EXPECT_THROW(Obstacle::cylinder(Vec3::Zero(), Vec3::Zero(), 1.0), std::invalid_argument);
  EXPECT_THROW(Obstacle::plane(Vec3::Zero(), Vec3::Zero()), std::invalid_argument);
  EXPECT_THROW(Obstacle::level_set([](const Vec3&) { return 0.0; }, "0", "", 0.0), std::invalid_argument);
}

// A definition whose obstacles are replaced by fixed ones.
void replace_obstacles(ProblemDefinition* d, std::vector<Obstacle> obstacles) {
  d->obstacles = std::move(obstacles);
  d->moving_obstacles = {};
  d->obstacle_parameters.clear();
}

// The active-set loop on `d` finds one contact, with the force and arclength of `expected`.
void expect_single_contact_like(const ProblemDefinition& d, const RodPoint& guess, const PointContact& expected,
                                double tolerance) {
  const ContactSolveResult found = solve_with_contacts(d, guess);
  ASSERT_TRUE(found.complementarity) << found.message;
  ASSERT_EQ(found.definition.contacts.size(), 1u);
  EXPECT_NEAR(found.definition.contacts[0].force / expected.force, 1.0, tolerance);
  EXPECT_NEAR(found.definition.contacts[0].s, expected.s, tolerance);
}

// --- three-point bending by a disc (cases/indenter.toml) ----------------------------------

struct IndenterRun {
  Case c;
  ContactSolveResult solve;
  std::unique_ptr<ShootingProblem> problem;
  Solution solution;
};

IndenterRun indent(const ParameterOverrides& overrides) {
  IndenterRun r;
  r.c = load_case(testing::case_path("indenter.toml"), overrides);
  r.solve = solve_with_contacts(r.c.definition, r.c.start_guess);
  EXPECT_TRUE(r.solve.result.summary.converged()) << r.solve.result.summary.brief_report();
  EXPECT_TRUE(r.solve.complementarity) << r.solve.message;
  r.problem = std::make_unique<ShootingProblem>(r.solve.definition);
  r.solution = make_solution(*r.problem, r.solve.result, 401, {"contact_force", "contact_s", "kappa_contact", "min_gap"});
  return r;
}

TEST(DiscContact, ThreePointBendingAgreesWithTheEllipticSolutionForEveryRadius) {
  const auto exact = analytic::three_point_bending(1.0, 1.0, kSupportSlope);
  // From a pin of radius 0.2 down to 1e-5: the rod touches the top of the disc at mid-span, so the
  // solution does not depend on the radius; a sharp point is the limit.
  for (double radius : {0.2, 0.05, 1e-3, 1e-5}) {
    SCOPED_TRACE(radius);
    const IndenterRun r = indent({{"radius", radius}, {"half_span", exact.half_span}, {"rise", exact.rise}});
    ASSERT_EQ(r.solution.contacts.size(), 1u);
    const auto& d = r.solution.derived;
    // Newton to 1e-10 on forces ~10 with RK tolerances ~1e-12: ~1e-11 relative; 1e-9 is the bar.
    EXPECT_NEAR(d.at("contact_force") / exact.force, 1.0, 1e-9);
    EXPECT_NEAR(d.at("contact_s"), 0.5, 1e-9);  // symmetry, not imposed
    EXPECT_NEAR(d.at("kappa_contact") / exact.kappa_mid, 1.0, 1e-9);
    const RodPoint end = r.problem->sample(r.solve.result.x, {1.0}).front();
    EXPECT_NEAR(end.r.x(), 2.0 * exact.half_span, 1e-9);  // where the roller went
    EXPECT_GE(d.at("min_gap"), -1e-10);
    EXPECT_LE(r.solution.invariants.H.relative_spread(), 1e-9);  // H across the contact
  }
}

TEST(DiscContact, OffCentreTheReactionPassesThroughTheCentre) {
  // Moved sideways, the contact slides around the disc and the pin takes a horizontal force.
  const double centre_x = 0.6, radius = 0.1, top = 0.15;
  const IndenterRun r = indent({{"half_span", centre_x}, {"rise", top}, {"radius", radius}});
  ASSERT_EQ(r.solution.contacts.size(), 1u);
  const PointContact& contact = r.solution.contacts[0];
  EXPECT_GT(contact.force, 0.0);
  const auto ends = r.problem->sample(r.solve.result.x, {0.0, contact.s, 1.0});
  const Vec3 centre(centre_x, top - radius, 0.0);
  // On the disc, and tangent to it.
  EXPECT_NEAR((ends[1].r - centre).norm(), radius, 1e-11);
  EXPECT_NEAR((ends[1].r - centre).normalized().dot(ends[1].R.col(2)), 0.0, 1e-9);
  const Vec3 nu = (ends[1].r - centre).normalized();
  EXPECT_GT(std::abs(nu.x()), 0.05);  // really off the top
  // Global equilibrium: n(L) - n(0) = -F nu, and with m = 0 at both ends the end reactions have no
  // moment about the centre, through which the contact force passes. Tolerances: forces ~10 to
  // the solver's 1e-10.
  EXPECT_LE((ends[2].n - ends[0].n + contact.force * nu).norm(), 1e-9);
  const double moment = (ends[2].r - centre).cross(ends[2].n).z() - (ends[0].r - centre).cross(ends[0].n).z();
  EXPECT_NEAR(moment, 0.0, 1e-9);
  EXPECT_GT(std::abs(ends[0].n.x()), 0.1);  // the pin's horizontal reaction
  EXPECT_LE(r.solution.invariants.H.relative_spread(), 1e-9);
  EXPECT_GE(r.solution.derived.at("min_gap"), -1e-10);
}

TEST(DiscContact, TheSameDiscAsALevelSetGivesTheSameSolution) {
  const IndenterRun cylinder = indent({{"radius", 0.1}});
  Case c = load_case(testing::case_path("indenter.toml"), {{"radius", 0.1}});
  const Vec3 centre = c.definition.obstacles[0].point();
  const auto g = [centre](const Vec3& r) { return std::hypot(r.x() - centre.x(), r.y() - centre.y()) - 0.1; };
  replace_obstacles(&c.definition, {Obstacle::level_set(g, "disc", "indenter", 1e-4)});
  // Fourth-order differences with h = 1e-4 on a radius 0.1: gradient error ~1e-11.
  expect_single_contact_like(c.definition, c.start_guess, cylinder.solution.contacts[0], 1e-9);
}

TEST(DiscContact, ContinuationInTheIndentersHeightFromFirstContact) {
  // The disc starts 0.02 below the straight rod and rises; the contact appears where the rod
  // first touches it, at rise = 0 (located to the event tolerance), and the branch ends on the
  // closed form.
  const auto exact = analytic::three_point_bending(1.0, 1.0, kSupportSlope);
  Case c = load_case(testing::case_path("indenter.toml"), {{"rise", -0.02}});
  c.definition.contacts.clear();  // nothing touches the straight rod
  RodContinuationOptions o;
  o.parameter = "rise";
  o.target = exact.rise;
  o.initial_step = 0.01;
  o.max_step = 1.0;
  o.max_points = 400;
  o.derived = {"contact_force", "contact_s", "min_gap", "min_contact_force"};
  const testing::ContactBranch branch = testing::follow_contacts(c, o);
  ASSERT_EQ(branch.result.result.reason, StopReason::ReachedTarget) << branch.result.result.message;
  ASSERT_EQ(branch.result.changes.size(), 1u);
  EXPECT_NE(branch.result.changes[0].find("a contact appears"), std::string::npos) << branch.result.changes[0];
  double first_contact = NAN;
  for (const auto& p : branch.points) {
    if (!p.event.empty()) first_contact = p.parameter;
    EXPECT_GE(p.derived.at("min_gap"), -1e-9) << p.parameter;
    if (std::isfinite(p.derived.at("min_contact_force"))) EXPECT_GE(p.derived.at("min_contact_force"), -1e-9);
  }
  // The event sits at min_gap = -1e-9 (an active contact touches with gap 0 up to round-off).
  EXPECT_NEAR(first_contact, 0.0, 2e-9);
  const ContinuationPoint& last = branch.points.back();
  EXPECT_NEAR(last.parameter, exact.rise, 1e-12);
  EXPECT_NEAR(last.derived.at("contact_force") / exact.force, 1.0, 1e-9);
  EXPECT_NEAR(last.derived.at("contact_s"), 0.5, 1e-9);
}

// --- wrapping around a disc (cases/wrapped_indenter.toml) --------------------------------

TEST(DiscWrap, ClosedFormStartsWhereThePointContactsCurvatureReachesTheDisc) {
  // At the radius 1 / |kappa_mid| of the point-contact solution the wrap has zero length: the
  // wrapped closed form continues the point-contact one (difference ~ the radius' offset, 1e-7).
  const auto point = analytic::three_point_bending(1.0, 1.0, kSupportSlope);
  const double onset = 1.0 / std::abs(point.kappa_mid);
  const auto wrapped = analytic::three_point_bending_wrapped(1.0, 1.0, onset * (1 + 1e-7), kSupportSlope);
  EXPECT_NEAR(wrapped.force / point.force, 1.0, 1e-6);
  EXPECT_NEAR(wrapped.contact_start, 0.5, 1e-6);
  EXPECT_NEAR(wrapped.half_span, point.half_span, 1e-6);
  EXPECT_NEAR(wrapped.rise, point.rise, 1e-6);
  EXPECT_THROW(analytic::three_point_bending_wrapped(1.0, 1.0, onset * (1 - 1e-7), kSupportSlope), std::invalid_argument);
  EXPECT_THROW(analytic::three_point_bending_wrapped(1.0, 1.0, 1.0, kSupportSlope), std::invalid_argument);  // longer than L/2
}

// The wrap of a solved indenter: on the disc, curved as it, n along the tangent, and the
// concentrated and distributed reactions in global equilibrium with the supports.
void expect_admissible_wrap(const ShootingProblem& problem, const Eigen::VectorXd& x, const PointContact& wrap,
                            const Vec3& centre, double radius) {
  ASSERT_TRUE(wrap.extended);
  EXPECT_GT(wrap.force, 0.0);
  EXPECT_GT(wrap.force_end, 0.0);
  std::vector<double> s;
  for (int i = 0; i <= 20; ++i) s.push_back(wrap.s + (wrap.s_end - wrap.s) * i / 20.0);
  const auto on = problem.sample(x, s);
  const double tension = on[10].n.dot(on[10].R.col(2));
  EXPECT_GT(tension, 0.0);
  for (size_t i = 0; i < on.size(); ++i) {
    // The wrap's closed form is a rotation: exact to round-off on quantities ~1 (forces ~10).
    const RodPoint& p = on[i];
    EXPECT_NEAR((p.r - centre).norm(), radius, 1e-12);
    EXPECT_NEAR((p.r - centre).dot(p.R.col(2)), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(p.u[1]), 1.0 / radius, 1e-12);
    if (i + 1 == on.size()) break;  // sampled at s_end, n is the state after that edge's force
    EXPECT_NEAR(p.n.dot(p.R.col(2)), tension, 1e-12);
    // The entry's "no normal force" row, solved by Newton to 1e-10.
    EXPECT_NEAR(p.n.dot(p.R.col(0)), 0.0, 1e-9);
  }
  // Global balance: every reaction of the disc is radial, so the end reactions have no moment about
  // its centre; and n(L) - n(0) = -(F1 nu1 + F2 nu2) + N (t2 - t1), the pressure's resultant.
  const auto ends = problem.sample(x, {0.0, 1.0});
  const Vec3 nu1 = (on.front().r - centre) / radius, nu2 = (on.back().r - centre) / radius;
  const Vec3 resultant = -wrap.force * nu1 - wrap.force_end * nu2 + tension * (on.back().R.col(2) - on.front().R.col(2));
  EXPECT_LE((ends[1].n - ends[0].n - resultant).norm(), 1e-9);
  const double moment = (ends[1].r - centre).cross(ends[1].n).z() - (ends[0].r - centre).cross(ends[0].n).z();
  EXPECT_NEAR(moment, 0.0, 1e-9);
}

TEST(DiscWrap, CaseAgreesWithTheEllipticSolution) {
  // Two radii and slopes; the case's guess is the same rough wrap [0.45, 0.55] for both.
  for (const auto& [radius, slope_deg] : {std::pair{0.5, -35.0}, std::pair{0.25, -70.0}}) {
    SCOPED_TRACE(radius);
    const auto exact = analytic::three_point_bending_wrapped(1.0, 1.0, radius, slope_deg * M_PI / 180.0);
    const Case c = load_case(testing::case_path("wrapped_indenter.toml"),
                             {{"radius", radius}, {"half_span", exact.half_span}, {"rise", exact.rise}});
    const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
    ASSERT_TRUE(r.complementarity) << r.message;
    const ShootingProblem problem(r.definition);
    const Solution sol = make_solution(problem, r.result, 401, {"n_y", "min_wrap_tension", "min_gap"});
    ASSERT_EQ(sol.contacts.size(), 1u);
    const PointContact& wrap = sol.contacts[0];
    // Newton to 1e-10 with RK tolerances ~1e-12 on forces ~10: 1e-9 relative is the bar.
    EXPECT_NEAR(wrap.s, exact.contact_start, 1e-9);
    EXPECT_NEAR(wrap.s_end, 1.0 - exact.contact_start, 1e-9);  // symmetry, not imposed
    EXPECT_NEAR(wrap.force / exact.edge_force, 1.0, 1e-9);
    EXPECT_NEAR(wrap.force_end / exact.edge_force, 1.0, 1e-9);
    EXPECT_NEAR(sol.derived.at("min_wrap_tension") / exact.tension, 1.0, 1e-9);
    EXPECT_NEAR(sol.derived.at("n_y") / (0.5 * exact.force), 1.0, 1e-9);
    EXPECT_GE(sol.derived.at("min_gap"), -1e-10);
    EXPECT_LE(sol.invariants.H.relative_spread(), 1e-9);  // H across both edges and the wrap
    expect_admissible_wrap(problem, r.result.x, wrap, Vec3(exact.half_span, exact.rise - radius, 0.0), radius);
  }
}

RodContinuationOptions rising_indenter(double target) {
  RodContinuationOptions o;
  o.parameter = "rise";
  o.target = target;
  o.initial_step = 0.01;
  o.max_step = 1.0;
  o.max_points = 600;
  o.derived = {"contact_force", "kappa_contact", "contact_length", "min_gap", "min_contact_force", "min_wrap_tension"};
  return o;
}

TEST(DiscWrap, ContinuationFromFirstContactIntoTheWrap) {
  // A disc of radius 0.5 a little right of the rod's middle rises from below: the rod touches it,
  // its curvature at the contact reaches 2, and the contact spreads around the disc in tension.
  const double radius = 0.5, centre_x = 0.5, target = 0.18;
  Case c = load_case(testing::case_path("wrapped_indenter.toml"),
                     {{"radius", radius}, {"half_span", centre_x}, {"rise", -0.02}});
  c.definition.contacts.clear();
  const testing::ContactBranch branch = testing::follow_contacts(c, rising_indenter(target));
  ASSERT_EQ(branch.result.result.reason, StopReason::ReachedTarget) << branch.result.result.message;
  ASSERT_EQ(branch.result.changes.size(), 2u);
  EXPECT_NE(branch.result.changes[0].find("a contact appears"), std::string::npos) << branch.result.changes[0];
  EXPECT_NE(branch.result.changes[1].find("starts to wrap"), std::string::npos) << branch.result.changes[1];
  bool wrapped = false;
  double previous_length = 0.0;
  for (const auto& p : branch.points) {
    EXPECT_GE(p.derived.at("min_gap"), -1e-9) << p.parameter;
    if (std::isfinite(p.derived.at("min_contact_force"))) EXPECT_GE(p.derived.at("min_contact_force"), -1e-9);
    if (!p.event.empty() && p.event.find("wrap") != std::string::npos) {
      // Located where the curvature at the contact is the disc's (the event's tolerance).
      EXPECT_NEAR(p.derived.at("kappa_contact"), -1.0 / radius, 1e-8);
      wrapped = true;
      continue;
    }
    if (!wrapped) continue;
    EXPECT_GT(p.derived.at("min_wrap_tension"), 0.0) << p.parameter;
    EXPECT_GE(p.derived.at("contact_length"), previous_length) << p.parameter;  // it only spreads here
    previous_length = p.derived.at("contact_length");
  }
  ASSERT_TRUE(wrapped);
  EXPECT_GT(previous_length, 0.1);
  // The end point: an admissible wrap, and the same solution the active-set loop finds from the
  // case's rough guess at that height (two independent paths).
  const ContinuationPoint& last = branch.points.back();
  const ShootingProblem& problem = *branch.problems.back();
  const auto contacts = problem.contacts_at(last.x);
  ASSERT_EQ(contacts.size(), 1u);
  expect_admissible_wrap(problem, last.x, contacts[0], Vec3(centre_x, target - radius, 0.0), radius);
  const Case direct = load_case(testing::case_path("wrapped_indenter.toml"),
                                {{"radius", radius}, {"half_span", centre_x}, {"rise", target}});
  const ContactSolveResult r = solve_with_contacts(direct.definition, direct.start_guess);
  ASSERT_TRUE(r.complementarity) << r.message;
  ASSERT_EQ(r.definition.contacts.size(), 1u);
  EXPECT_NEAR(r.definition.contacts[0].s, contacts[0].s, 1e-9);
  EXPECT_NEAR(r.definition.contacts[0].s_end, contacts[0].s_end, 1e-9);
  EXPECT_NEAR(r.definition.contacts[0].force, contacts[0].force, 1e-8);
  EXPECT_NEAR(r.definition.contacts[0].force_end, contacts[0].force_end, 1e-8);
}

TEST(DiscWrap, LoweringTheDiscUnwindsTheWrapAndTheContactLiftsOff) {
  // The way back from the end of the run above: from the wrap the active-set loop finds at
  // rise = 0.18, the disc is lowered below the rod. The wrap shrinks to a point where the forward
  // run saw it start, and the point contact lifts off where the forward run's first touched.
  const double radius = 0.5, centre_x = 0.5;
  Case c = load_case(testing::case_path("wrapped_indenter.toml"),
                     {{"radius", radius}, {"half_span", centre_x}, {"rise", 0.18}});
  const testing::ContactBranch back = testing::follow_contacts(c, rising_indenter(-0.01));
  ASSERT_EQ(back.result.result.reason, StopReason::ReachedTarget) << back.result.result.message;
  ASSERT_EQ(back.result.changes.size(), 2u);
  EXPECT_NE(back.result.changes[0].find("shrinks to a point"), std::string::npos) << back.result.changes[0];
  EXPECT_NE(back.result.changes[1].find("lifts off"), std::string::npos) << back.result.changes[1];
  std::vector<double> at;
  for (const auto& p : back.points) {
    if (!p.event.empty()) at.push_back(p.parameter);
    EXPECT_GE(p.derived.at("min_gap"), -1e-9) << p.parameter;
    if (std::isfinite(p.derived.at("min_contact_force"))) EXPECT_GE(p.derived.at("min_contact_force"), -1e-9);
    if (std::isfinite(p.derived.at("min_wrap_tension"))) EXPECT_GT(p.derived.at("min_wrap_tension"), 0.0);
  }
  ASSERT_EQ(at.size(), 2u);
  // The forward run, for the heights of its events.
  Case up = c;
  up.definition.parameters.set("rise", -0.02);
  up.definition.contacts.clear();
  const testing::ContactBranch forward = testing::follow_contacts(up, rising_indenter(0.18));
  std::vector<double> forward_at;
  for (const auto& p : forward.points)
    if (!p.event.empty()) forward_at.push_back(p.parameter);
  ASSERT_EQ(forward_at.size(), 2u);
  // Events are located by secant steps on smooth functions of the height: to ~1e-10 here.
  EXPECT_NEAR(at[0], forward_at[1], 1e-8);  // unwound where it started to wrap
  EXPECT_NEAR(at[1], forward_at[0], 2e-9);  // lifted off where it touched (both at 0 up to the gap event's 1e-9)
}

TEST(DiscWrap, ReachingTheDiscsCurvatureInCompressionStopsWithAClearMessage) {
  // Disc left of the rod's middle: the contact is on the rod's rising side, where n.t < 0; a wrap
  // there would pull on the disc (pressure = tension / radius), so the rod would touch it at two
  // points instead - not modelled, and said so.
  Case c = load_case(testing::case_path("wrapped_indenter.toml"), {{"half_span", 0.4}, {"rise", -0.02}});
  c.definition.contacts.clear();
  const testing::ContactBranch branch = testing::follow_contacts(c, rising_indenter(0.3));
  EXPECT_EQ(branch.result.result.reason, StopReason::Inadmissible);
  EXPECT_NE(branch.result.result.message.find("in compression"), std::string::npos) << branch.result.result.message;
  EXPECT_NE(branch.result.result.message.find("not implemented"), std::string::npos);
  EXPECT_NEAR(branch.points.back().derived.at("kappa_contact"), -2.0, 1e-6);
}

TEST(DiscWrap, OnlyDiscsAndPlanesTakeExtendedContacts) {
  // A level-set disc: same shape, but the wrap's closed form is the cylinder's; refused with why.
  Case c = load_case(testing::case_path("wrapped_indenter.toml"));
  replace_obstacles(&c.definition, {Obstacle::level_set([](const Vec3& r) { return r.norm() - 0.5; }, "|r| - 0.5")});
  try {
    const ShootingProblem problem(c.definition);
    ADD_FAILURE() << "an extended contact on a level set was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not implemented"), std::string::npos) << e.what();
  }
}

// --- 3D: a twisted anisotropic rod against a pole (cases/twisted_ribbon_pole.toml) ---------

TEST(SpatialContact, PlanarWallCaseGivesTheSameForcesIn3D) {
  // wall.toml as a spatial rod along e_z buckling towards a wall x = a: the 3D core meets the wall
  // exactly as the planar restriction does.
  const Case planar = load_case(testing::case_path("wall.toml"));
  const ContactSolveResult expected = solve_with_contacts(planar.definition, planar.start_guess);
  ASSERT_TRUE(expected.complementarity);
  Case spatial = load_case(testing::case_path("twisted_ribbon_pole.toml"), {{"phi", 0.0}});
  replace_obstacles(&spatial.definition, {Obstacle::plane(Vec3(0.1, 0, 0), Vec3(-1, 0, 0), "wall")});
  spatial.definition.model = [inner = spatial.definition.model](const Parameters& p) {
    RodModel m = inner(p);
    m.B[1] = Profile(1.0);  // isotropic as wall.toml (its circle of copies is broken by phi = 0 and the wall)
    return m;
  };
  // Two integrations at 1e-12 and Newton to 1e-12: 1e-9 is the bar.
  expect_single_contact_like(spatial.definition, spatial.start_guess, expected.definition.contacts[0], 1e-9);
}

TEST(SpatialContact, TwistedRibbonLeansOnAPole) {
  const Case c = load_case(testing::case_path("twisted_ribbon_pole.toml"));
  const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_TRUE(r.result.summary.converged()) << r.result.summary.brief_report();
  ASSERT_TRUE(r.complementarity) << r.message;
  ASSERT_EQ(r.definition.contacts.size(), 1u);
  const PointContact& contact = r.definition.contacts[0];
  EXPECT_GT(contact.force, 0.1);
  const ShootingProblem problem(r.definition);
  const Solution sol = make_solution(problem, r.result, 401, {"min_gap", "H"});
  const double s = contact.s;
  // Either side of the contact (for n) and on it (for the geometry).
  const auto at = problem.sample(r.result.x, {0.0, s - 1e-9, s, s + 1e-9, 1.0});
  const RodPoint &start = at[0], &before = at[1], &on = at[2], &after = at[3], &end = at[4];
  // Really three-dimensional: the contact is off the plane of the clamps' common axis and e_x.
  EXPECT_GT(std::abs(on.r.y()), 1e-3);
  // On the pole and tangent to it; the force along the offset from its axis.
  const Vec3 centre(0.15, 0.0, 0.517), axis = Vec3::UnitY();
  Vec3 d = on.r - centre;
  d -= d.dot(axis) * axis;
  EXPECT_NEAR(d.norm(), 0.1, 1e-11);
  EXPECT_NEAR(d.dot(on.R.col(2)), 0.0, 1e-11);
  EXPECT_LE((after.n - before.n + contact.force * d.normalized()).norm(), 1e-8 * contact.force);
  // Global balance of moments about the contact point, through which the contact force passes;
  // forces ~40 to 1e-12.
  const Vec3 moment = (end.r - on.r).cross(end.n) + end.m - (start.r - on.r).cross(start.n) - start.m;
  EXPECT_LE(moment.norm(), 1e-9);
  // H is the same on both sides (the jump is normal to the tangent) and flat along the rod.
  EXPECT_LE(sol.invariants.H.relative_spread(), 1e-10);
  EXPECT_GE(sol.derived.at("min_gap"), -1e-10);
}

// --- Ipopt with a disc ------------------------------------------------------------------------

TEST(DiscContact, IpoptConvergesToTheShootingSolutionAtSecondOrder) {
  // wall.toml's clamped-clamped rod pushed up into a disc of radius 0.1 whose bottom is at the
  // wall's height a = 0.1, above mid-span: the contact is found from the free arch. Centred, so
  // that the contact (s = L/2) is a node of every even N: the discrete model has no contact
  // arclength, only nodes, so off a node its forces converge at first order, irregularly (an
  // off-centre disc locked its discrete contact on s = 0.47 for N = 100..800 while the rod
  // touches at 0.46987; energy agreed to 1e-7, n_y to 7e-4 only).
  const double radius = 0.1, centre_x = 0.5 * (1.0 - 0.026);
  Case c = load_case(testing::case_path("wall.toml"));
  const Obstacle disc = Obstacle::cylinder(Vec3(centre_x, 0.1 + radius, 0.0), Vec3::UnitZ(), radius, "disc");
  replace_obstacles(&c.definition, {disc});  // (wall.toml's wall follows its parameter a)
  const ContactSolveResult shooting = solve_with_contacts(c.definition, c.start_guess);
  ASSERT_TRUE(shooting.complementarity) << shooting.message;
  ASSERT_EQ(shooting.definition.contacts.size(), 1u);
  const ShootingProblem problem(shooting.definition);
  const Solution exact = make_solution(problem, shooting.result, 101, {"P", "contact_force", "contact_s"});
  EXPECT_NEAR(exact.derived.at("contact_s"), 0.5, 1e-9);
  std::vector<double> error_P, error_F;
  for (int N : {50, 100, 200}) {
    const DiscreteElasticaResult d = solve_discrete_clamped_elastica(1.0, 1.0, 0.026, {disc}, N, 0.1);
    ASSERT_TRUE(d.converged) << d.status;
    EXPECT_GE(d.min_gap, -1e-12);
    error_P.push_back(std::abs(d.P - exact.derived.at("P")));
    error_F.push_back(std::abs(d.contact_force - exact.derived.at("contact_force")));
  }
  // Second order: halving h divides the error by 4.
  for (int k = 0; k + 1 < 3; ++k) {
    EXPECT_NEAR(error_P[k] / error_P[k + 1], 4.0, 0.4) << k;
    EXPECT_NEAR(error_F[k] / error_F[k + 1], 4.0, 0.4) << k;
  }
  EXPECT_LT(error_P.back() / exact.derived.at("P"), 1e-3);
}

}  // namespace
}  // namespace kirchhoff
