// The stability index a continuation records at each point (point_record.cpp) integrates the
// Jacobi fields to RodRecordOptions::stability_field_tolerance, looser than the state's. The index
// is a count (phase passages through pi, singular values against zero_tolerance = 1e-6), so the
// looser fields must give the very same index and zero modes as the state's tolerance at every
// point, through the branch points and folds where the index changes: checked here along
// branches whose index changes, against analyse_stability with the fields at the state's
// tolerance. (They agree on these branches even with fields to 5e-4; a recorder that reports
// zero modes against 1e-2 instead of 1e-6 fails on the Euler column at its branch points.)
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/jobs/case_continue.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

struct Recorded {
  ShootingProblem problem;  // at the point's parameter
  Eigen::VectorXd x;
  std::optional<int> index;
  int zero_modes = 0;
};

struct KeepPoints : ContinueSink {
  std::string parameter;
  std::vector<Recorded> points;
  void begin(const std::string& name, const std::vector<std::string>&, int) override { parameter = name; }
  void point(const RunPoint& p) override {
    ASSERT_NE(p.problem, nullptr) << "a plain run";
    points.push_back({*p.problem, p.point->x, p.point->stability_index, p.point->zero_modes});
    points.back().problem.set_parameter(parameter, p.point->parameter);
  }
};

// Runs the request and compares every point's recorded index with the state's tolerance's;
// returns the distinct indices met (so that a test can require that the index changed).
std::set<int> expect_same_indices(const std::string& file, const ParameterOverrides& overrides,
                                  const ContinueRequest& request) {
  const Case c = load_case(testing::case_path(file), overrides);
  KeepPoints keep;
  const ContinueRunResult result = continue_case(c, request, {&keep});
  EXPECT_TRUE(result.ok) << result.message;
  StabilityOptions tight;
  tight.extended_contacts = false;
  tight.field_tolerance = 0.0;
  std::set<int> seen;
  for (size_t i = 0; i < keep.points.size(); ++i) {
    const Recorded& p = keep.points[i];
    const StabilityReport reference = analyse_stability(p.problem, p.x, tight);
    EXPECT_EQ(p.index, reference.index) << file << ", point " << i << ": " << reference.reason;
    EXPECT_EQ(p.zero_modes, reference.zero_modes) << file << ", point " << i;
    if (p.index) seen.insert(*p.index);
  }
  EXPECT_GT(keep.points.size(), 20u);
  return seen;
}

// A run of `parameter` towards `target`, profiles at 21 points (the index does not use them).
ContinueRequest towards(const std::string& parameter, double target, double max_step) {
  ContinueRequest r;
  r.parameter = parameter;
  r.target = target;
  r.max_step = max_step;
  r.samples = 21;
  return r;
}

TEST(StabilityAlongBranches, LooserFieldsAreLooserThanTheState) {
  // Otherwise the tests below compare a computation with itself.
  EXPECT_GT(RodRecordOptions{}.stability_field_tolerance, IntegratorOptions{}.abs_tol);
}

TEST(StabilityAlongBranches, EulerColumnThroughItsFirstTwoBranchPoints) {
  // Past (2 pi)^2 = 39.5: index 0, 1, 2 on the straight column.
  const ContinueRequest r = towards("P", 45.0, 1.0);
  const std::set<int> seen = expect_same_indices("euler_column.toml", {{"P", 1.0}, {"theta_guess", 0.0}}, r);
  EXPECT_EQ(seen, (std::set<int>{0, 1, 2}));
}

TEST(StabilityAlongBranches, EulerColumnsFirstBuckledBranch) {
  ContinueRequest r = towards("P", 12.0, 1.0);
  r.switch_at_bp = 1;
  r.events = {{"theta0", 3.0, true, ""}};
  const std::set<int> seen = expect_same_indices("euler_column.toml", {{"P", 1.0}, {"theta_guess", 0.0}}, r);
  EXPECT_TRUE(seen.count(0) && seen.count(1)) << "the straight column's index 1 and the stable branch";
}

TEST(StabilityAlongBranches, TwistedRodPastTheGreenhillTwistAndOntoTheBuckledBranch) {
  ContinueRequest r = towards("phi", 15.0, 1.0);
  r.switch_at_bp = 1;
  r.events = {{"end_to_end", 0.5, true, ""}};
  const std::set<int> seen = expect_same_indices("twisted_clamped.toml", {{"phi", 6.0}, {"tension", 0.0}}, r);
  EXPECT_GE(seen.size(), 2u);
}

TEST(StabilityAlongBranches, ClampedClampedRodUnderEndShortening) {
  // Both ends held: the isoperimetric correction at every point.
  ContinueRequest r = towards("D", 0.3, 0.05);
  r.direction = -1.0;
  const std::set<int> seen = expect_same_indices("clamped_clamped.toml", {{"s_mode", 1.0}}, r);
  EXPECT_TRUE(seen.count(1)) << "the S-shaped mode";
}

// The straight column at P = 20 continued in EI down to 0.05 and 0.04: a branch point at each
// EI = 20 / (k pi)^2, index k - 1 there with one zero mode. The last step of each run overshoots
// its target past several branch points (its candidate at EI = 0.0247, index 9); the branch point
// before the target was settled against that candidate instead of the target's point, and got
// four zero modes (0.05) and seven (0.04), from a probe.
struct KeepBranchPoints : ContinueSink {
  std::vector<std::pair<double, std::pair<std::optional<int>, int>>> rows;  // EI, (index, zero modes)
  void point(const RunPoint& p) override {
    if (p.point->type == PointType::BranchPoint)
      rows.push_back({p.point->parameter, {p.point->stability_index, p.point->zero_modes}});
  }
};

TEST(StabilityAlongBranches, ABranchPointBeforeTheTargetIsSettledAgainstTheTargetsPoint) {
  for (const double target : {0.05, 0.04}) {
    SCOPED_TRACE(target);
    const Case c = load_case(testing::case_path("euler_column.toml"), {{"P", 20.0}, {"theta_guess", 0.0}});
    ContinueRequest r;
    r.parameter = "EI";
    r.target = target;
    r.samples = 21;
    KeepBranchPoints keep;
    ASSERT_TRUE(continue_case(c, r, {&keep}).ok);
    ASSERT_GE(keep.rows.size(), 5u);
    for (const auto& [EI, count] : keep.rows) {
      const double k = std::sqrt(20.0 / EI) / M_PI;  // whole at a branch point
      // (Branch points are located to 1e-13 in EI here, 6e-8 at worst on other targets: 1e-6 in k
      // leaves room, and the next k is 1 away.)
      EXPECT_NEAR(k, std::round(k), 1e-6) << EI;
      EXPECT_EQ(count.first, static_cast<int>(std::round(k)) - 1) << EI;
      EXPECT_EQ(count.second, 1) << EI;
    }
  }
}

// The shallow arch's symmetric branch meets the asymmetric one at w = 39.2597 (a pitchfork: its
// two sides are mirror images, index 1). The first step along the switching direction, 0.05,
// failed its corrector on one side (start_failed, "no solution along the switching direction")
// and not on the other (a probe); it is halved now, as a march's step is, and both sides start.
struct KeepBranches : ContinueSink {
  std::vector<std::pair<int, std::optional<int>>> rows;  // branch, index
  void point(const RunPoint& p) override { rows.push_back({p.branch, p.point->stability_index}); }
};

TEST(StabilityAlongBranches, BothSidesOfTheShallowArchsPitchforkAreReached) {
  for (const double side : {1.0, -1.0}) {
    SCOPED_TRACE(side);
    const Case c = load_case(testing::case_path("shallow_arch.toml"));
    ContinueRequest r = towards("w", 200.0, 0.5);
    r.switch_at_bp = 1;
    r.switch_side = side;
    r.max_points = 140;
    KeepBranches keep;
    const ContinueRunResult result = continue_case(c, r, {&keep});
    EXPECT_NE(result.status, "start_failed") << result.message;
    int on_branch = 0;
    for (const auto& [branch, index] : keep.rows)
      if (branch == 1 && on_branch++ > 0) EXPECT_EQ(index, 1);  // past its origin (the branch point)
    EXPECT_GT(on_branch, 5);
  }
}

}  // namespace
}  // namespace kirchhoff
