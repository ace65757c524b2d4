// Section 7.2 / Fig. 5: the Elastica buckled in a cavity (cavity.toml: clamps half-way between
// the walls y = a and y = -a). Continued in the end shortening, the rod goes through point
// contact, extended contact and hanging fold with the contact set changed automatically; H is
// the same on both sides of every contact, and an extended contact and a hanging fold never
// coexist on one rod.
#include <cmath>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/point_record.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

testing::ContactBranch follow_cavity(double target) {
  const Case c = load_case(testing::case_path("cavity.toml"));
  RodContinuationOptions o;
  o.parameter = "Delta";
  o.target = target;
  o.max_step = 2.0;
  o.max_points = 6000;
  o.derived = {"P", "H", "kappa_contact", "contact_s", "min_gap", "min_contact_force"};
  return testing::follow_contacts(c, o);
}

class Cavity : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { branch = new testing::ContactBranch(follow_cavity(0.1)); }
  static void TearDownTestSuite() { delete branch; }
  static testing::ContactBranch* branch;
};
testing::ContactBranch* Cavity::branch = nullptr;

TEST_F(Cavity, PointContactThenExtendedContactThenHangingFold) {
  const auto& r = branch->result;
  ASSERT_EQ(r.result.reason, StopReason::ReachedTarget) << r.result.message;
  ASSERT_EQ(r.changes.size(), 3u);
  EXPECT_NE(r.changes[0].find("a contact appears with obstacle 0 at s = 0.5"), std::string::npos) << r.changes[0];
  EXPECT_NE(r.changes[1].find("flattens into an extended contact"), std::string::npos) << r.changes[1];
  EXPECT_NE(r.changes[2].find("a hanging fold"), std::string::npos) << r.changes[2];
  // The event points carry the changes, in the same order, at increasing Delta; the first is
  // where the free arch's crest reaches the upper wall, the third where P l^2 = 4 pi^2 EI.
  std::vector<double> at;
  for (const auto& p : branch->points)
    if (p.type == PointType::Event) at.push_back(p.parameter);
  ASSERT_EQ(at.size(), 3u);
  EXPECT_LT(at[0], at[1]);
  EXPECT_LT(at[1], at[2]);
  // Against elliptic-function solutions, to 5e-6: where H = -P (from the flattening on) the
  // clamps' curvature is a double root and the Jacobian singular (contact.cpp), so residuals of
  // 1e-10 leave errors ~1e-6 (observed 5.5e-7 at the flattening, 1.2e-6 at the fold's onset).
  EXPECT_NEAR(at[1] / analytic::contact_flattening(1.0, 1.0, 0.1).Delta, 1.0, 5e-6);
  EXPECT_NEAR(at[2] / analytic::flat_contact_buckling(1.0, 1.0, 0.1).Delta, 1.0, 5e-6);
  // With the clamps half-way, the blister's lowest point stays above y = 0 (it reaches it only
  // where the fold's forces vanish, see below): the lower wall is never touched.
  for (size_t i = 0; i < branch->points.size(); ++i)
    for (const auto& c : branch->contacts(i)) EXPECT_EQ(c.obstacle, 0);
}

TEST_F(Cavity, HIsTheSameOnBothSidesOfEveryContactAndTheForcesPush) {
  for (size_t i = 0; i < branch->points.size(); ++i) {
    const ContinuationPoint& p = branch->points[i];
    EXPECT_LE(invariants_of(p).H.relative_spread(), 1e-9) << p.parameter;
    // (The contact-appearance event is located where min_gap = -1e-9, the loop's tolerance.)
    EXPECT_GE(p.derived.at("min_gap"), -1.01e-9) << p.parameter;
    for (const auto& c : branch->contacts(i)) {
      EXPECT_GE(c.force, 0.0) << p.parameter;
      EXPECT_GE(c.extended ? c.force_end : 0.0, 0.0) << p.parameter;
      for (double s : {c.s, c.extended ? c.s_end : c.s}) {
        const auto [before, after] = testing::hamiltonian_across(*branch->problems[i], p.x, s);
        EXPECT_NEAR(before, after, 1e-9 * std::abs(before)) << p.parameter << " s = " << s;
      }
    }
  }
}

// Section 7.2: n_x = -P everywhere (frictionless walls). On a flat contact theta = 0 and kappa = 0,
// so H = n3 = -P there, and H is one number along the rod. At a fold's contact theta = 0 but the
// rod curves away from the wall, kappa_c != 0, so H = EI kappa_c^2 / 2 - P > -P. One rod cannot
// have both: H would take two values. On the branch, every point with a flat contact has
// H + P = 0 and every fold has H + P = kappa_c^2 / 2 > 0, and none has both.
TEST_F(Cavity, ExtendedContactAndHangingFoldNeverCoexist) {
  int flat = 0, folds = 0;
  for (size_t i = 0; i < branch->points.size(); ++i) {
    const ContinuationPoint& p = branch->points[i];
    const auto contacts = branch->contacts(i);
    const double P = p.derived.at("P"), H_plus_P = p.derived.at("H") + P;
    EXPECT_FALSE(has_extended_contact(contacts) && has_hanging_fold(contacts)) << p.parameter;
    if (has_extended_contact(contacts) && contacts.front().s_end > contacts.front().s) {
      ++flat;
      EXPECT_NEAR(H_plus_P, 0.0, 1e-9 * P) << p.parameter;
    }
    if (has_hanging_fold(contacts)) {
      ++folds;
      const double kc = p.derived.at("kappa_contact");
      EXPECT_NEAR(H_plus_P, 0.5 * kc * kc, 1e-9 * P) << p.parameter;
      EXPECT_GT(H_plus_P, 1e-6 * P) << p.parameter;  // far from the flat value, not within round-off
    }
  }
  EXPECT_GT(flat, 100);
  EXPECT_GT(folds, 20);
}

// Further on, the fold's contact forces fall to zero at once, at s = L/4 and 3L/4, where the rod
// is the free clamped-clamped Elastica in its second symmetric mode with its crests on the wall
// (elliptic solution). Beyond, the fold's forces would pull and the free rod penetrates the wall:
// the admissible branch turns back there, and the run reports that instead of following either.
TEST(CavityBeyond, FoldContactsLiftOffTogetherWhereTheSecondModeTouches) {
  const testing::ContactBranch branch = follow_cavity(0.2);
  EXPECT_EQ(branch.result.result.reason, StopReason::Inadmissible) << branch.result.result.message;
  const ContinuationPoint* lift = nullptr;
  for (const auto& p : branch.points)
    if (p.event.find("lifts off") != std::string::npos && !lift) lift = &p;
  ASSERT_NE(lift, nullptr);
  const auto exact = analytic::second_mode_arches(1.0, 1.0, 0.1);
  // Located by the secant method on the smallest force (1e-10): Delta and P to ~1e-9.
  EXPECT_NEAR(lift->parameter / exact.Delta, 1.0, 1e-8);
  EXPECT_NEAR(lift->derived.at("P") / exact.P, 1.0, 1e-8);
  EXPECT_NEAR(lift->derived.at("contact_s"), 0.25, 1e-8);
  // Nothing reported after it breaks complementarity.
  for (const auto& p : branch.points) {
    EXPECT_GE(p.derived.at("min_gap"), -1e-6) << p.parameter;
    if (std::isfinite(p.derived.at("min_contact_force"))) EXPECT_GE(p.derived.at("min_contact_force"), -1e-6);
  }
}

TEST(CavityBadInput, ClampsOutsideTheCavityAreInfeasible) {
  // a < 0 swaps the walls: the clamps at y = 0 are inside both.
  const Case c = load_case(testing::case_path("cavity.toml"), {{"a", -0.05}});
  RodContinuationOptions o;
  o.parameter = "Delta";
  o.target = 0.01;
  EXPECT_THROW(continue_with_contacts(c.definition, c.start_guess, o), InfeasibleContact);
}

}  // namespace
}  // namespace kirchhoff
