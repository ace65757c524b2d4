// Self-contact by the half-turn symmetry (self_contact.hpp) and the symmetric plectoneme case
// (cases/plectoneme.toml, section 7.6, eqs. 58-61).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/point_record.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/contact/self_contact.hpp"
#include "kirchhoff/contact/self_passage.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/equations/integrator.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

HalfTurnSelfContactOptions contact_options() {
  HalfTurnSelfContactOptions o;
  o.radius = 0.01;
  o.axis = Vec3(1.0, 0.0, 0.0);
  o.symmetry_s = 0.5;
  o.strength = 1e-6;
  o.range = 0.0025;
  o.adjacent = 0.02;
  return o;
}

// The force is minus the gradient of the potential and its gradient is the Jacobian the
// variational equations use: central differences (step 1e-7 on lengths ~1e-3, so truncation
// ~1e-14 and round-off ~1e-16 * |V| / 1e-7) agree to 1e-6 relative.
TEST(HalfTurnSelfContact, ForceIsMinusGradientOfPotential) {
  const HalfTurnSelfContact contact(contact_options());
  const double s = 0.3;
  for (const Vec3& r : {Vec3(0.1, 0.0105, 0.0), Vec3(0.2, 0.008, 0.0071), Vec3(-0.05, -0.0009, 0.0112)}) {
    const Vec3 f = contact.force(s, r);
    const Mat3 G = contact.force_gradient(s, r);
    const double h = 1e-7;
    for (int i = 0; i < 3; ++i) {
      Vec3 e = Vec3::Zero();
      e[i] = h;
      const double dV = (contact.potential(s, r + e) - contact.potential(s, r - e)) / (2 * h);
      EXPECT_NEAR(f[i], -dV, 1e-6 * f.norm()) << "component " << i;
      const Vec3 df = (contact.force(s, r + e) - contact.force(s, r - e)) / (2 * h);
      EXPECT_LT((G.col(i) - df).norm(), 1e-6 * G.norm()) << "column " << i;
    }
    // Repulsive, across the axis, away from it.
    EXPECT_NEAR(f.x(), 0.0, 1e-15 * f.norm());
    EXPECT_GT(f.dot(Vec3(0.0, r.y(), r.z())), 0.0);
  }
}

TEST(HalfTurnSelfContact, ImageDistanceAndSwitchOff) {
  const HalfTurnSelfContact contact(contact_options());
  const Vec3 r(0.3, 0.004, -0.012);
  EXPECT_NEAR((r - contact.geometry().image(r)).norm(), 2.0 * contact.geometry().distance_to_axis(r), 1e-16);
  EXPECT_EQ(contact.weight(0.0), 1.0);
  EXPECT_EQ(contact.weight(0.5 - 0.04), 1.0);
  EXPECT_EQ(contact.weight(0.5 - 0.02), 0.0);
  EXPECT_GT(contact.weight(0.47), 0.0);
  EXPECT_LT(contact.weight(0.47), 1.0);
  EXPECT_EQ(contact.potential(0.49, Vec3(0.3, 0.0, 0.0)), 0.0);  // the end loop crosses the axis freely
  EXPECT_TRUE(std::isnan(contact.gap(0.49, r)));
  EXPECT_THROW(contact.force(0.1, Vec3(0.3, 0.0, 0.005)), IntegrationError);  // inside the other strand
}

TEST(HalfTurnSelfContact, RefusesNonPhysicalOptions) {
  auto o = contact_options();
  o.radius = -1.0;
  EXPECT_THROW(HalfTurnSelfContact{o}, std::invalid_argument);
  o = contact_options();
  o.strength = 0.0;
  EXPECT_THROW(HalfTurnSelfContact{o}, std::invalid_argument);
  o = contact_options();
  o.adjacent = 0.3;  // longer than half the half rod
  EXPECT_THROW(HalfTurnSelfContact{o}, std::invalid_argument);
}

// Untwisted, the half rod with a half-turn end is the planar clamped-clamped Elastica with its
// ends end_distance*L apart: T_ext = -16 K(k)^2 EI/L^2 with 2E/K - 1 = D/L. The shooting solve
// converges to 1e-8 in |F| (the case's tolerance) at forces ~50, hence 1e-9 relative.
TEST(Plectoneme, UntwistedIsTheClampedClampedElastica) {
  for (double D : {0.5, 0.8}) {
    const double guess_P = analytic::clamped_clamped_elastica_load(1.0, 1.0, D);
    const auto solved = testing::solve_case(
        "plectoneme.toml", {{"end_distance", D}, {"guess_n", -guess_P}, {"guess_m", 2.0 * std::sqrt(guess_P) * 0.68}});
    const double T = solved.solution.derived.at("T_ext");
    EXPECT_NEAR(-T / guess_P, 1.0, 1e-9) << "D = " << D;
    EXPECT_NEAR(solved.solution.derived.at("m3"), 0.0, 1e-12);
    EXPECT_LT(solved.solution.invariants.H.spread, 1e-9 * std::abs(solved.solution.invariants.H.mean));
  }
}

// The half-turn end conditions are right when the whole rod, integrated from the half rod's
// clamp with no symmetry assumed, ends at the mirror clamp: z = +D/2 on e3, turned by +pi*turns
// about e3, with the clamp's reactions mirrored. Twisted (turns = 0.3, the rod out of its plane)
// and before any contact. The integration runs at 1e-12 over forces ~40 and a unit length: 1e-8.
TEST(Plectoneme, WholeRodFromTheHalfEndsAtTheMirrorClamp) {
  const double turns = 0.3, D = 0.8;
  const auto solved = testing::solve_case("plectoneme.toml", {{"turns", turns}, {"end_distance", D}});
  ASSERT_GT(solved.solution.derived.at("self_distance"), 1.2);  // far from contact: no field needed
  RodModel whole;
  whole.length = 1.0;
  whole.B = {Profile(1.0), Profile(1.0), Profile(solved.c.definition.parameters.get("GJ"))};
  const auto eq = make_spatial_equations(whole);
  const Eigen::VectorXd y0 = solved.problem->start_state(solved.solution.result.x);
  const RodPoint end = eq->point(eq->flow(y0, 0.0, 1.0, false, IntegratorOptions{}).y, 1.0);
  const RodPoint start = solved.solution.profile.front();
  EXPECT_LT((end.r - Vec3(0.0, 0.0, 0.5 * D)).norm(), 1e-8);
  const Mat3 mirror_clamp = Eigen::AngleAxisd(M_PI * turns, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_LT((end.R - mirror_clamp).norm(), 1e-8);
  // n(L) = -S n(0) and m(L) = -S m(0) for the half-turn S about e1 (internal force and moment
  // change sign with the direction of the arclength).
  const Mat3 S = Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix();
  EXPECT_LT((end.n + S * start.n).norm(), 1e-8 * start.n.norm());
  EXPECT_LT((end.m + S * start.m).norm(), 1e-8 * start.m.norm());
}

// Twisting the clamped rod (L/2R = 100, D = L/2) from the planar Elastica: it leaves its plane,
// forms an end loop that closes on itself (self-contact appears with no contact set given) and
// winds into a ply. Along the whole branch: no two cross-sections closer than 2R (over all pairs,
// not only the symmetric ones the barrier acts on), m3 and H conserved - H_A = H_B, the argument
// of eqs. (59)-(60), with the barrier's potential in H. In the ply (turns 5):
// m3 against the helix's eq. (58b) and T_ext against eq. (61), both with the computed helix
// radius rho (R plus the barrier's gap) and angle. The bars are the helical approximation's
// accuracy on a ply of a few turns between a tail and an end loop, as measured (1-2 % and 2-7 %
// over turns 4-6.6): 4 % and 12 %.
TEST(Plectoneme, TwistingWindsAPlyThatFollowsTheHelixFormulas) {
  Case c = load_case(testing::case_path("plectoneme.toml"));
  ShootingProblem problem(c.definition);
  ShootingResult start = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(start.summary.converged());
  RodContinuationOptions o;
  o.parameter = "turns";
  o.target = 5.0;
  o.initial_step = 1.0;
  o.max_step = 60.0;
  o.max_points = 2000;
  o.derived = c.derived;
  o.samples = 1001;
  o.detect_branch_points = false;  // the barrier's stiffness makes the determinant's sign noise
  RodContinuation run(problem, o);
  const ContinuationResult branch = run.run(start.x);
  ASSERT_EQ(branch.reason, StopReason::ReachedTarget) << branch.message;
  int folds = 0, in_contact = 0;
  for (const auto& p : branch.points) {
    folds += p.type == PointType::Fold;
    EXPECT_GE(p.derived.at("self_distance"), 1.0 - 1e-9) << "turns " << p.parameter;
    // Against |m|, the size of the terms m3 is read from: RK78 at 1e-12 to 1e-13 per step on
    // states whose forces reach ~50-500, over ~1e3 steps, leaves ~1e-9 of it; the bar is ten
    // times that.
    EXPECT_LT(invariants_of(p).m3.relative_spread(), 1e-8) << "turns " << p.parameter;
    const double H_A = p.derived.at("H_A"), H_B = p.derived.at("H_B");
    if (std::isnan(H_A)) continue;
    ++in_contact;
    // The worst point is where the loop first closes: the contact there is a crossing whose
    // barrier force is a spike ~sqrt(R g) wide, which RK78 at the case's 1e-13 resolves to
    // ~1.2e-9 of H (at 1e-12, 2.1e-8).
    EXPECT_NEAR(H_A, H_B, 1e-8 * std::max(1.0, std::abs(H_B))) << "turns " << p.parameter;
    EXPECT_GT(p.derived.at("contact_pressure"), 0.0);
    EXPECT_GT(p.derived.at("loop_clearance"), 4.0);
  }
  EXPECT_GE(folds, 2);
  EXPECT_GT(in_contact, 10) << "self-contact never appeared";
  const auto& ply = branch.points.back().derived;
  const double theta = ply.at("helix_angle"), rho = ply.at("helix_radius"), EI = 1.0;
  ASSERT_TRUE(theta > 0.1 && theta < 0.5) << theta;
  EXPECT_LT(rho / 0.005, 1.3);  // the strands touch: rho = R plus a gap
  EXPECT_NEAR(ply.at("m3") / analytic::helix_twisting_moment(theta, EI, rho), 1.0, 0.04);
  EXPECT_NEAR(ply.at("T_ext") * rho * rho / EI / analytic::plectoneme_end_tension(theta, 1.0, 1.0), 1.0, 0.12);
}

// At L/2R = 500 the branch from the untwisted rod folds at 1.77 turns and again, sharply, at
// 1.034 (T_ext = 62.7147, m3 = 0.2044). A step of the length that suits the rest of the branch
// (the plectonemes command's modified-Newton steps: arclength 25-1500 here) crosses
// that fold onto the neighbouring sheet: m3 changes sign and the run continues through the mirror
// fold (0.2296 turns) to the untwisted Elastica's shape at 2 turns - the rod has passed through
// itself. With the SelfPassageGuard the same run refuses that step and turns at the fold.
TEST(Plectoneme, SelfPassageGuardKeepsTheBranchAtTheSharpFold) {
  Case c = load_case(testing::case_path("plectoneme.toml"), {{"slenderness", 500.0}});
  const double scale = 25.0;  // forces ~ 1/R^2, relative to L/2R = 100 (the case's tolerance)
  c.definition.options.newton.residual_tolerance *= scale;
  ShootingProblem problem(c.definition);
  const ShootingResult start = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(start.summary.converged());
  RodContinuationOptions o;
  o.parameter = "turns";
  o.initial_step = 1.0 * scale;
  o.max_step = 60.0 * scale;
  o.max_points = 26;
  o.corrector_tolerance = 1e-8 * scale;
  o.modified_newton = true;
  o.corrector_max_iterations = 16;
  o.grow_iterations = 10;
  o.shrink_iterations = 14;
  o.reuse_jacobian_iterations = 8;
  o.detect_branch_points = false;
  o.derived = {"T_ext", "m3"};
  o.samples = 101;
  // The unguarded run used to jump at the fold onto a sheet two turns on (m3 < 0): the start
  // frame's twist was gauged into (-pi, pi] and jumped by 2 pi where the clamp passes half a turn
  // (turns = 1, just before this fold), which the corrector could exploit. With the twist gauged
  // modulo whole turns (spatial_equations.cpp) that jump is gone; what is checked here is that the
  // guarded run stays on the branch through the sharp fold and locates it.
  RodContinuationOptions guarded_options = o;
  ASSERT_TRUE(guard_self_passage(problem, &guarded_options));
  const ContinuationResult guarded = RodContinuation(problem, guarded_options).run(start.x);
  auto after_first_fold = [](const ContinuationResult& r) {
    std::vector<ContinuationPoint> out;
    bool folded = false;
    for (const auto& p : r.points) {
      if (folded) out.push_back(p);
      folded |= p.type == PointType::Fold;
    }
    return out;
  };
  int folds = 0;
  for (const auto& p : after_first_fold(guarded)) {
    EXPECT_GT(p.derived.at("m3"), 0.2) << "turns " << p.parameter;
    if (p.type != PointType::Fold) continue;
    ++folds;
    // Where the fold is located depends on the steps that bracket it: 1.0338034 and T_ext
    // 62.714307 with the full-Newton steps (on the sheet reached through the rod, 2 turns on),
    // 1.0338315 and 62.714653 with these. The bars take in both.
    EXPECT_NEAR(p.parameter, 1.03383, 1e-4);
    EXPECT_NEAR(p.derived.at("T_ext"), 62.7145, 1e-3);
  }
  EXPECT_EQ(folds, 1);
}

// cases/plectoneme.toml with one piece of its text replaced, written to a temporary file.
std::string edited_case(const std::vector<std::pair<std::string, std::string>>& replacements) {
  std::ifstream in(testing::case_path("plectoneme.toml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const auto& [from, to] : replacements) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  const std::string path = testing::scratch_path("plectoneme_edited.toml");
  std::ofstream(path) << text;
  return path;
}

// The `rotation` form of the half_turn end imposes the end frame's turn about the axis and
// solves for `turns`: given the turn of a solution found the usual way, it finds the same
// solution (turns = 0.3 back to the Newton tolerance over the clamp's sensitivity, 1e-8).
TEST(Plectoneme, ImposedLoopRotationGivesBackTheTurns) {
  const auto usual = testing::solve_case("plectoneme.toml", {{"turns", 0.3}});
  const Vec3 d3 = usual.solution.profile.back().R.col(2);
  const double beta = std::atan2(-d3.y(), d3.z());  // the tip frame is Rot_e1(beta) at identity
  const std::string path = edited_case({{"director = 1", "director = 1\nrotation = \"beta\""},
                                        {"turns = 0.0 ", "beta = 0.0\nturns = 0.0 "},
                                        {"[solver]\n", "[solver]\nunknowns = [\"turns\"]\n"}});
  Case c = load_case(path, {{"beta", beta}, {"turns", 0.2}});
  ShootingProblem problem(c.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
  EXPECT_NEAR(r.parameters.get("turns"), 0.3, 1e-8);
}

// Bad input names the file, the key and the reason.
TEST(Plectoneme, CaseErrorsNameTheKey) {
  auto refused = [&](const std::string& from, const std::string& to, const std::string& expected) {
    const std::string path = edited_case({{from, to}});
    try {
      load_case(path);
      ADD_FAILURE() << "accepted: " << to;
    } catch (const CaseError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("radius = \"L/(2*slenderness)\"", "radius = \"-L/(2*slenderness)\"", "rod.self_contact.radius");
  refused("radius = \"L/(2*slenderness)\"", "radius = \"L/(2*slenderness)\", softnes = 1", "rod.self_contact.softnes");
  refused("director = 1", "director = 3", "end.director");
  refused("[start]\ntype = \"clamped\"\nposition = [0, 0, \"-end_distance*L/2\"]\n"
          "orientation = { axis = [0, 0, 1], angle = \"-_pi*turns\" }",
          "[start]\ntype = \"half_turn\"\naxis = [1, 0, 0]", "start.type");
}

}  // namespace
}  // namespace kirchhoff
