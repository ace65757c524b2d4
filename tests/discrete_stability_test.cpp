// The discretised-energy index (discrete_stability.hpp) against closed forms, and against the
// conjugate-point index (stability.hpp) on every planar case the suite solves without contacts.
// Indices and zero-mode counts are integers and compared exactly; eigenvalues against closed forms
// with the discretisation's own O(h^2) error, stated beside each comparison.
#include "kirchhoff/discrete_stability.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "kirchhoff/stability.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

using testing::solve_case;

constexpr int kElements = 400;
constexpr double kH = 1.0 / kElements;  // every rod here has L = 1

struct Solved {
  std::unique_ptr<ShootingProblem> problem;
  Eigen::VectorXd x;
};

Solved solve_shipped(const std::string& name, const ParameterOverrides& overrides) {
  testing::Solved s = solve_case(name, overrides);
  return {std::move(s.problem), s.solution.result.x};
}

Solved solve_text(const std::string& text, const ParameterOverrides& overrides) {
  const Case c = load_case_text(text, "inline.toml", overrides);
  Solved out{std::make_unique<ShootingProblem>(c.definition), {}};
  const ShootingResult r = solve(*out.problem, out.problem->initial_unknowns(c.start_guess));
  EXPECT_TRUE(r.summary.converged()) << r.summary.brief_report();
  out.x = r.x;
  return out;
}

// The closed form's eigenvalues k = 1, 2, ... against the discrete ones: the bending operator
// -d/ds (B d/ds) on a mode of wave number q is approximated by (4 / h^2) sin^2(q h / 2)
// = q^2 - q^4 h^2 / 12 + ..., while the trapezoid-weighted load terms are exact on these modes, so
// each eigenvalue is low by q^4 h^2 / 12 at most (the series alternates), and by at least 0.99 of
// it for q h <= 0.15 (the next term is q^6 h^4 / 360). The dense eigensolver adds round-off of
// ~eps times the largest eigenvalue, 4 B / h^2 = 6.4e5 here: 1e-8 covers it.
void expect_closed_form(const DiscreteStability& d, const std::vector<double>& wave_numbers, double P) {
  constexpr double kRoundOff = 1e-8;
  ASSERT_EQ(d.lowest_eigenvalues.size(), wave_numbers.size());
  for (size_t k = 0; k < wave_numbers.size(); ++k) {
    const double q = wave_numbers[k], bound = std::pow(q, 4) * kH * kH / 12;
    SCOPED_TRACE("mode " + std::to_string(k + 1));
    EXPECT_GE(d.lowest_eigenvalues[k], q * q - P - bound - kRoundOff);
    EXPECT_LE(d.lowest_eigenvalues[k], q * q - P - 0.99 * bound + kRoundOff);
  }
}

// The pinned column under the dead load P, straight: second variation int (dtheta'^2 - P dtheta^2)
// with natural conditions dtheta'(0) = dtheta'(L) = 0 and the roller's y(L) = 0, i.e.
// int dtheta = 0. The Neumann modes cos(k pi s), k >= 0, diagonalise it; the constraint removes
// k = 0 (the rigid rotation about the pin), leaving (k pi)^2 - P, k = 1, 2, ...
TEST(DiscreteStability, StraightPinnedColumnHasEigenvaluesKPiSquaredMinusP) {
  for (double P : {5.0, 20.0, 50.0, 100.0}) {
    SCOPED_TRACE("P = " + std::to_string(P));
    const Solved s = solve_shipped("euler_column.toml", {{"P", P}, {"theta_guess", 0.0}});
    const DiscreteStability d = discrete_stability(*s.problem, s.x, kElements);
    ASSERT_TRUE(d.defined()) << d.reason;
    EXPECT_TRUE(d.trustworthy) << d.check_message;
    std::vector<double> q;
    int below = 0;
    for (int k = 1; k <= kDiscreteStabilityReported; ++k) {
      q.push_back(k * M_PI);
      below += k * k * M_PI * M_PI < P ? 1 : 0;
    }
    expect_closed_form(d, q, P);
    EXPECT_EQ(*d.index, below);
    EXPECT_EQ(d.zero_modes, 0);
  }
}

const char* kCantilever = R"(
model = "planar"
[parameters]
P = 5.0
[rod]
length = 1.0
B = 1.0
[start]
type = "clamped"
position = [0, 0]
[end]
type = "loaded"
force = ["-P", 0]
moment = [0, 0, 0]
[guess]
force = ["-P", 0]
)";

// Clamped at s = 0, free under the dead load P at s = L: dtheta(0) = 0, dtheta'(L) = 0, no
// constraint, so the modes are sin((k - 1/2) pi s) with eigenvalues ((k - 1/2) pi)^2 - P.
TEST(DiscreteStability, StraightCantileverHasEigenvaluesOfTheFreeEnd) {
  for (double P : {1.0, 5.0, 25.0}) {
    SCOPED_TRACE("P = " + std::to_string(P));
    const Solved s = solve_text(kCantilever, {{"P", P}});
    const DiscreteStability d = discrete_stability(*s.problem, s.x, kElements);
    ASSERT_TRUE(d.defined()) << d.reason;
    EXPECT_TRUE(d.trustworthy) << d.check_message;
    std::vector<double> q;
    for (int k = 1; k <= kDiscreteStabilityReported; ++k) q.push_back((k - 0.5) * M_PI);
    expect_closed_form(d, q, P);
    EXPECT_EQ(*d.index, P < 0.25 * M_PI * M_PI ? 0 : (P < 2.25 * M_PI * M_PI ? 1 : 2));
  }
}

const char* kFreeFree = R"(
model = "planar"
[parameters]
P = 5.0
[rod]
length = 1.0
B = 1.0
[start]
type = "loaded"
force = ["P", 0]
moment = [0, 0, 0]
[end]
type = "loaded"
force = ["-P", 0]
moment = [0, 0, 0]
[guess]
force = ["-P", 0]
)";

// Both ends free under opposite dead loads: nothing is held, so the two rigid translations are
// zero modes, and the rigid rotation dtheta = const has eigenvalue -P (the loads' couple): unstable
// under compression, stable under tension; the other modes are the Neumann ones, (k pi)^2 - P.
TEST(DiscreteStability, FreeRodCountsTranslationsAsZeroModesAndRotationAsMinusP) {
  for (double P : {-5.0, 5.0}) {
    SCOPED_TRACE("P = " + std::to_string(P));
    const Solved s = solve_text(kFreeFree, {{"P", P}});
    const DiscreteStability d = discrete_stability(*s.problem, s.x, kElements);
    ASSERT_TRUE(d.defined()) << d.reason;
    EXPECT_TRUE(d.trustworthy) << d.check_message;
    EXPECT_EQ(d.zero_modes, 2);
    EXPECT_EQ(*d.index, P > 0 ? 1 : 0);
    const std::vector<double>& mu = d.lowest_eigenvalues;
    const double rotation = P > 0 ? mu[0] : *std::min_element(mu.begin(), mu.end(), [&](double a, double b) {
      return std::abs(a + P) < std::abs(b + P);
    });
    EXPECT_NEAR(rotation, -P, 1e-9 * std::abs(P));  // the constant mode has no bending error
  }
}

struct Row {
  std::string label;
  std::string case_name;  // a shipped case
  ParameterOverrides overrides;
  int index = 0;       // known independently (Euler loads, the issue's acceptance list)
  int zero_modes = 0;
};

// Both indices and both zero-mode counts equal, and equal to the known ones, with the discrete
// check trustworthy.
void expect_agreement(const Row& row) {
  SCOPED_TRACE(row.label);
  const Solved s = solve_shipped(row.case_name, row.overrides);
  const StabilityReport conjugate = analyse_stability(*s.problem, s.x);
  const DiscreteStability d = discrete_stability(*s.problem, s.x, kElements);
  ASSERT_TRUE(conjugate.defined()) << conjugate.reason;
  ASSERT_TRUE(d.defined()) << d.reason;
  EXPECT_TRUE(d.trustworthy) << d.check_message;
  EXPECT_EQ(*d.index, *conjugate.index);
  EXPECT_EQ(d.zero_modes, conjugate.zero_modes);
  EXPECT_EQ(*d.index, row.index);
  EXPECT_EQ(d.zero_modes, row.zero_modes);
}

TEST(DiscreteStability, AgreesWithConjugatePointsOnTheEulerColumn) {
  const std::vector<Row> rows = {
      {"straight P = 5", "euler_column.toml", {{"P", 5.0}, {"theta_guess", 0.0}}, 0},
      {"straight P = 20", "euler_column.toml", {{"P", 20.0}, {"theta_guess", 0.0}}, 1},
      {"straight P = 50", "euler_column.toml", {{"P", 50.0}, {"theta_guess", 0.0}}, 2},
      {"straight P = 100", "euler_column.toml", {{"P", 100.0}, {"theta_guess", 0.0}}, 3},
      {"mode 1, P = 12", "euler_column.toml", {{"P", 12.0}, {"theta_guess", 1.0}}, 0},
      // Past the point where the ends meet the first mode loses its stability.
      {"mode 1 past the ends meeting, P = 30", "euler_column.toml", {{"P", 30.0}, {"theta_guess", 2.5}}, 1},
      {"mode 2, P = 50", "euler_column.toml", {{"P", 50.0}, {"theta_guess", 1.0}}, 1},
      {"mode 3, P = 100", "euler_column.toml", {{"P", 100.0}, {"theta_guess", 1.5}}, 2},
  };
  for (const Row& row : rows) expect_agreement(row);
}

// P is a multiplier: the end shortening is held. At theta0 = 2.8 the shooting solution has its
// ends at one point, so turning the whole rod about the shared pin keeps every constraint: a
// zero mode.
TEST(DiscreteStability, AgreesWithConjugatePointsOnTheSimplySupportedElastica) {
  for (const Row& row : {Row{"theta0 = 1", "simply_supported.toml", {{"theta0", 1.0}}, 0, 0},
                         Row{"theta0 = 2", "simply_supported.toml", {{"theta0", 2.0}}, 0, 0},
                         Row{"theta0 = 2.8, ends meet", "simply_supported.toml", {{"theta0", 2.8}}, 0, 1}})
    expect_agreement(row);
}

TEST(DiscreteStability, AgreesWithConjugatePointsOnTheClampedRodWithImposedShortening) {
  for (const Row& row : {Row{"symmetric, up", "clamped_clamped.toml", {}, 0},
                         Row{"symmetric, down", "clamped_clamped.toml", {{"side", -1.0}}, 0},
                         Row{"S-shaped", "clamped_clamped.toml", {{"s_mode", 1.0}}, 1}})
    expect_agreement(row);
}

// The shipped planar cases that solve without contacts, as shipped and at loads where they are
// unstable (the tapered column above its first and second buckling loads, the arch after its
// asymmetric branch point). Their indices are the conjugate-point count's; the discrete check is
// the independent evidence.
TEST(DiscreteStability, AgreesWithConjugatePointsOnTheShippedPlanarCases) {
  const std::vector<Row> rows = {
      {"heavy_cantilever", "heavy_cantilever.toml", {}, 0},
      {"tapered", "tapered.toml", {}, 0},
      {"tapered_column", "tapered_column.toml", {}, 0},
      {"tapered_column P = 20", "tapered_column.toml", {{"P", 20.0}}, 1},
      {"tapered_column P = 60", "tapered_column.toml", {{"P", 60.0}}, 2},
      {"shallow_arch", "shallow_arch.toml", {}, 0},
      {"shallow_arch w = 20", "shallow_arch.toml", {{"w", 20.0}}, 0},
      {"shallow_arch w = 40", "shallow_arch.toml", {{"w", 40.0}}, 1},
  };
  for (const Row& row : rows) expect_agreement(row);
}

// Close to a branch point the discretisation error exceeds the eigenvalue: at P = pi^2 - 1e-4 the
// lowest eigenvalue is +1e-4, but -pi^4 h^2 / 12 = -2.0e-4 at N/2 = 200 elements flips it. The
// check says the sign is not decided instead of returning a number.
TEST(DiscreteStability, SelfCheckRefusesAnIndexWithinTheDiscretisationError) {
  const Solved s = solve_shipped("euler_column.toml", {{"P", M_PI * M_PI - 1e-4}, {"theta_guess", 0.0}});
  const DiscreteStability d = discrete_stability(*s.problem, s.x, kElements);
  ASSERT_TRUE(d.defined()) << d.reason;
  EXPECT_FALSE(d.trustworthy);
  EXPECT_NE(d.check_message.find("disagree"), std::string::npos) << d.check_message;
  EXPECT_EQ(*analyse_stability(*s.problem, s.x).index, 0);  // the continuous answer
}

// Too few elements for the third buckled mode (its curvature changes over ~L/6): each check in
// turn catches it. At 10 elements the 5-element solve has no equilibrium near the sampled one; at
// 40 the discrete equilibrium is 0.018 rad from the shooting one; at 60 it is within 1e-2 rad but
// the lowest eigenvalue moves from -67.53 to -68.50 between 30 and 60 elements, more than 1 % of
// its bending and load parts together. From 100 elements on the check passes (the index is 2
// throughout).
TEST(DiscreteStability, SelfCheckRefusesAnUnresolvedEquilibrium) {
  const Solved s = solve_shipped("euler_column.toml", {{"P", 100.0}, {"theta_guess", 1.5}});
  for (const auto& [elements, message] : std::vector<std::pair<int, std::string>>{
           {10, "Newton did not converge"}, {40, "from the shooting one"}, {60, "not resolved"}}) {
    SCOPED_TRACE(std::to_string(elements) + " elements");
    const DiscreteStability d = discrete_stability(*s.problem, s.x, elements);
    ASSERT_TRUE(d.defined()) << d.reason;
    EXPECT_FALSE(d.trustworthy);
    EXPECT_NE(d.check_message.find(message), std::string::npos) << d.check_message;
  }
  EXPECT_TRUE(discrete_stability(*s.problem, s.x, 100).trustworthy);
}

// Unknowns that are not a solution: the discrete equilibrium Newton finds is far from them.
TEST(DiscreteStability, SelfCheckRefusesAPointThatIsNotTheEquilibrium) {
  Solved s = solve_shipped("euler_column.toml", {{"P", 12.0}, {"theta_guess", 1.0}});
  s.x[2] += 0.05;  // theta(0): the rod sampled from it is not in equilibrium
  const DiscreteStability d = discrete_stability(*s.problem, s.x, kElements);
  ASSERT_TRUE(d.defined()) << d.reason;
  EXPECT_FALSE(d.trustworthy);
  EXPECT_NE(d.check_message.find("from the shooting one"), std::string::npos) << d.check_message;
}

const char* kExtensible = R"(
model = "planar"
[rod]
length = 1.0
B = 1.0
extensible = true
A1 = 100.0
A3 = 100.0
[start]
type = "clamped"
position = [0, 0]
[end]
type = "loaded"
force = [0, -1]
moment = [0, 0, 0]
[guess]
force = [0, 1]
)";

TEST(DiscreteStability, UnsupportedCasesSayWhy) {
  struct Expected {
    std::string case_name;
    std::string reason;
  };
  for (const Expected& e : {Expected{"twisted_clamped.toml", "spatial"}, Expected{"indenter.toml", "active contacts"},
                            Expected{"soft_wall.toml", "depends on position"}, Expected{"sleeve.toml", "sleeve"}}) {
    SCOPED_TRACE(e.case_name);
    const Solved s = solve_shipped(e.case_name, {});
    const DiscreteStability d = discrete_stability(*s.problem, s.x);
    EXPECT_FALSE(d.defined());
    EXPECT_NE(d.reason.find(e.reason), std::string::npos) << d.reason;
    EXPECT_EQ(describe(d).rfind("discrete index undefined", 0), 0u);
  }
  const Solved s = solve_text(kExtensible, {});
  EXPECT_NE(discrete_stability(*s.problem, s.x).reason.find("extensible"), std::string::npos);
  const Solved column = solve_shipped("euler_column.toml", {{"P", 5.0}, {"theta_guess", 0.0}});
  EXPECT_NE(discrete_stability(*column.problem, column.x, 7).reason.find("even"), std::string::npos);
}

}  // namespace
}  // namespace kirchhoff
