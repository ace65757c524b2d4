// The index where the rod lies on an obstacle (an extended contact): the discretised energy with
// the nodes on the obstacle held (discrete_stability.hpp, detail/discrete_stability_lying.hpp), at
// two resolutions, and what analyse_stability reports from it (method "discretised_energy").
// Indices are integers and compared exactly; eigenvalues against closed forms with the
// discretisation's first-order error stated beside each comparison.
#include "kirchhoff/analysis/discrete_stability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "kirchhoff/jobs/result_json.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A shipped case solved as `kirchhoff solve` solves it (homotopy from the file's values, the
// contact set by the active-set loop), without the stability analysis.
CaseSolve solved(const std::string& name, const ParameterOverrides& overrides) {
  CaseSolveOptions options;
  options.solution = options.stability = options.stability_check = false;
  CaseSolve out = solve_case(load_case(testing::case_path(name), overrides), options);
  EXPECT_TRUE(out.failure.empty() && out.solved.result.summary.converged()) << out.message;
  return out;
}

PointContact extended_contact(const CaseSolve& s) {
  for (const PointContact& c : s.solved.problem->contacts_at(s.solved.result.x))
    if (c.extended) return c;
  ADD_FAILURE() << "no extended contact";
  return {};
}

// The rod wrapped on a disc presses on it everywhere (tension N > 0): every node there is held
// bilaterally, and the index is the same at 400 / 200 and 800 / 400 elements (at 400 the self-check
// asks for more: 2 % change of the lowest eigenvalue against its 1 %). The lowest eigenvalues stand
// far clear of zero (138.8 against a change of 0.47 between 400 and 800).
void expect_wrap_stable(const CaseSolve& s) {
  const ShootingProblem& problem = *s.solved.problem;
  const Eigen::VectorXd& x = s.solved.result.x;
  for (int elements : {400, 800}) {
    SCOPED_TRACE(std::to_string(elements) + " elements");
    const DiscreteStability d = discrete_stability(problem, x, elements);
    ASSERT_TRUE(d.defined()) << d.reason;
    EXPECT_EQ(*d.index, 0);
    EXPECT_EQ(d.zero_modes, 0);
    EXPECT_GT(d.lying_nodes, 10);
    EXPECT_EQ(d.weakly_active_nodes, 0);
    EXPECT_TRUE(std::isnan(d.lift_off_eigenvalue));
    ASSERT_FALSE(d.lowest_eigenvalues.empty());
    EXPECT_GT(d.lowest_eigenvalues[0], 10 * std::abs(d.lowest_eigenvalues[0] - d.coarse_eigenvalues[0]));
  }
  const StabilityReport report = analyse_stability(problem, x);
  ASSERT_TRUE(report.defined()) << report.reason;
  EXPECT_EQ(*report.index, 0);
  EXPECT_EQ(report.method, "discretised_energy");
  EXPECT_FALSE(report.method_reason.empty());
}

TEST(StabilityExtendedContact, WrappedIndenterIsStable) {
  const CaseSolve s = solved("wrapped_indenter.toml", {});
  const PointContact c = extended_contact(s);
  EXPECT_GT(c.s_end - c.s, 0.2);  // the closed form's wrap: [0.3775, 0.6225]
  expect_wrap_stable(s);
}

// The same rod pressed on the disc at another load (the disc raised: a shorter wrap).
TEST(StabilityExtendedContact, WrapAtAnotherLoadIsStable) {
  const CaseSolve s = solved("wrapped_indenter.toml", {{"rise", 0.18}});
  const PointContact c = extended_contact(s);
  EXPECT_GT(c.s_end - c.s, 0.0);
  expect_wrap_stable(s);
}

// Pushed further onto the disc (rise 0.19 to 0.21) the lowest eigenvalue, 130 to 265, changes by
// 1.1 to 2.3 % from 400 to 800 elements: first-order convergence, the sign decided by a factor of
// 20 or more. The self-check allows a contact 5 % (kDiscreteStabilityContactAgreement); at the 1 %
// of a rod without contact the index was null ("not resolved") at all three.
TEST(StabilityExtendedContact, WrapPushedFurtherIsStable) {
  for (const double rise : {0.19, 0.2, 0.21}) {
    SCOPED_TRACE("rise = " + std::to_string(rise));
    const CaseSolve s = solved("wrapped_indenter.toml", {{"rise", rise}});
    const StabilityReport report = analyse_stability(*s.solved.problem, s.solved.result.x);
    ASSERT_TRUE(report.defined()) << report.reason;
    EXPECT_EQ(*report.index, 0);
    EXPECT_EQ(report.zero_modes, 0);
  }
}

// The cavity as its rod starts to lie flat (Delta = 0.031): the flat part is so short that at 400
// elements no node lies between its edges, so its lift-off has nothing to compare with at N/2.
// The index is null and the reason says that ("nan at N/2" before).
TEST(StabilityExtendedContact, FlatPartTooShortAtHalfTheElementsSaysSo) {
  const CaseSolve s = solved("cavity.toml", {{"Delta", 0.031}});
  const StabilityReport report = analyse_stability(*s.solved.problem, s.solved.result.x);
  ASSERT_FALSE(report.defined());
  EXPECT_NE(report.reason.find("no node between its edges at N/2 elements"), std::string::npos) << report.reason;
  EXPECT_EQ(report.reason.find("nan"), std::string::npos) << report.reason;
}

// wall.toml past flattening (Delta = 0.04): the rod lies flat on the wall over [s1, s2] with the
// forces at the edges and none inside (weakly active). Two closed forms:
//  - the lift-off: the flat part is a strut clamped by the wall at its edges under the compression
//    P = -H, so its lowest eigenvalue per int dtheta^2 is (2 pi / l)^2 B - P (the mode
//    1 - cos(2 pi (s - s1) / l), which lifts everywhere), l = s2 - s1. The discrete strut spans
//    the angles strictly between the held edge nodes (the first node inside [s1, s2], and the last
//    of the same parity: every other node is held), so it is shorter than l by up to 4h: above
//    the closed form by up to 4h |d mu / d l| = 4h 2 (2 pi)^2 / l^3 (first order), and converging.
//  - the clamps are parallel to the wall, so H = -P makes their curvature zero, and each free arc
//    runs from zero curvature and angle at its clamp to zero curvature and angle at its edge:
//    dtheta = kappa(s) on one arc (its shift along itself) meets every condition (the clamp's
//    angle, the edge's angle and height, the chord: int sin(theta) kappa = int cos(theta) kappa
//    = 0) and is a Jacobi field, so the second variation has two zero modes. The discrete
//    eigenvalues approach them (from below, at first order), so the self-check cannot decide
//    their sign and the index is null with that reason - not a guessed 0 or 2.
TEST(StabilityExtendedContact, FlatContactOnTheWallLiftOffAndZeroModes) {
  const CaseSolve s = solved("wall.toml", {{"Delta", 0.04}});
  const ShootingProblem& problem = *s.solved.problem;
  const Eigen::VectorXd& x = s.solved.result.x;
  const PointContact c = extended_contact(s);
  const double l = c.s_end - c.s, P = -problem.sample(x, {0.5}).front().n.x();
  const double closed = std::pow(2 * kPi / l, 2) - P;
  std::vector<double> lowest, lift_error;
  for (int elements : {400, 800, 1600}) {
    SCOPED_TRACE(std::to_string(elements) + " elements");
    const double h = 1.0 / elements;
    const DiscreteStability d = discrete_stability(problem, x, elements);
    EXPECT_GT(d.weakly_active_nodes, 10);
    const double error = d.lift_off_eigenvalue - closed;
    EXPECT_GE(error, 0.0);
    EXPECT_LE(error, 4 * h * 2 * std::pow(2 * kPi, 2) / std::pow(l, 3));
    lift_error.push_back(error);
    ASSERT_GE(d.lowest_eigenvalues.size(), 3u);
    lowest.push_back(std::abs(d.lowest_eigenvalues[1]));
    // The third eigenvalue is a genuine positive one, far from the two zero modes.
    EXPECT_GT(d.lowest_eigenvalues[2], 50.0);
  }
  // Halving h roughly halves the two lowest (towards the zero modes): 0.7 leaves room for the
  // first-order rate's own error.
  EXPECT_LT(lift_error[2], lift_error[1]);
  EXPECT_LT(lift_error[1], lift_error[0]);
  EXPECT_LT(lowest[1], 0.7 * lowest[0]);
  EXPECT_LT(lowest[2], 0.7 * lowest[1]);
  const StabilityReport report = analyse_stability(problem, x);
  EXPECT_FALSE(report.defined());
  EXPECT_NE(report.reason.find("discretised energy"), std::string::npos) << report.reason;
}

// The same flat contacts at other shortenings: their two zero modes make the index undefined
// there too, never a count. The discrete eigenvalues tend to them unevenly (-4.20, -1.61, -1.18,
// -0.53 at 200 .. 1600 elements, Delta = 0.032; -5.43, -3.61, -2.70, -1.34 at 0.042), so 800
// against 400 alone passed -1.18 and -2.70 as negative: "unstable (index 2)". Just past the
// flattening the flat part is shorter than the discretisation's elements (8e-8 .. 1.6e-3 long at
// Delta = 0.0307490 .. 0.0308): one node held on the wall let the discrete rod rock about it,
// index 1 or 2 at both resolutions alike; it is now refused as too short.
TEST(StabilityExtendedContact, TheWallsFlatContactsAreNeverCounted) {
  for (const double delta : {0.0308, 0.032, 0.035, 0.042, 0.045}) {
    SCOPED_TRACE("Delta = " + std::to_string(delta));
    const CaseSolve s = solved("wall.toml", {{"Delta", delta}});
    const PointContact c = extended_contact(s);
    const StabilityReport report = analyse_stability(*s.solved.problem, s.solved.result.x);
    EXPECT_FALSE(report.defined());
    EXPECT_FALSE(report.unstable);
    const bool short_part = c.s_end - c.s < 2.0 / 400;
    EXPECT_NE(report.reason.find(short_part ? "too short for the discretised energy" : "within its discretisation error"),
              std::string::npos)
        << report.reason;
  }
}

// wall.toml with its clamps inclined towards the wall by 0.3 rad, pushed to Delta = 0.05: among its
// equilibria is a rod lying flat on the wall over [s1, s2] that the shooting splits into a flat
// contact over [s1, s] with no force at s and a point contact at s2 (the edge s is one of a
// continuum). It is one lying part of length l = s2 - s1 under the compression P = -H, past its
// Euler load when (2 pi / l)^2 < P: unstable by lifting off, its lift-off eigenvalue near
// (2 pi / l)^2 - P (above it by the shorter discrete strut, as above). It was reported undefined
// ("zero force at an edge").
TEST(StabilityExtendedContact, AFlatPartSplitByTheShootingIsOnePart) {
  std::string text = testing::case_text("wall.toml");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"m_guess = 2.0", "alpha = 0.3\nm_guess = 2.0"},
           {"position = [0, 0]\n", "position = [0, 0]\norientation = { axis = [0, 0, 1], angle = \"alpha\" }\n"},
           {"position = [\"L - Delta\", 0]\n",
            "position = [\"L - Delta\", 0]\norientation = { axis = [0, 0, 1], angle = \"-alpha\" }\n"}}) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  const Case c = load_case_text(text, "wall_inclined.toml", {{"Delta", 0.05}});
  EquilibriaOptions options;
  options.max_equilibria = 10;
  const EquilibriaSearch search = find_equilibria(c.definition, c.start_guess, c.derived, c.samples, options);
  int split = 0;
  for (const Equilibrium& e : search.equilibria) {
    const std::vector<PointContact> contacts = e.problem->contacts_at(e.solution.result.x);
    if (contacts.size() != 2 || !contacts[0].extended || contacts[1].extended) continue;
    ++split;
    const double l = contacts[1].s - contacts[0].s;
    const double P = -e.problem->sample(e.solution.result.x, {0.5 * (contacts[0].s_end + contacts[1].s)}).front().n.x();
    const double closed = std::pow(2 * kPi / l, 2) - P;
    ASSERT_LT(closed, 0.0);
    const StabilityReport& r = e.stability;
    EXPECT_FALSE(r.defined());
    EXPECT_TRUE(r.unstable) << r.reason;
    const DiscreteStability d = discrete_stability(*e.problem, e.solution.result.x);
    EXPECT_GE(d.lift_off_eigenvalue - closed, 0.0);
    EXPECT_LE(d.lift_off_eigenvalue - closed, 4.0 / 800 * 2 * std::pow(2 * kPi, 2) / std::pow(l, 3));
  }
  EXPECT_GE(split, 1);
}

// cavity.toml's flat contact past the onset of its buckling (analytic::flat_contact_buckling:
// the flat part a strut clamped by the wall at its edges, P l^2 = 4 pi^2 EI there), solved with
// the flat contact imposed from the onset's closed form (the continuation switches to the
// hanging fold at the onset instead). Past it the lift-off eigenvalue (2 pi / l)^2 B - P is
// negative: a perturbation lifting the flat part off the wall lowers the energy, so the
// equilibrium is unstable, though the lowering perturbations form a cone and no index is given.
// The two zero modes of the clamps parallel to the wall (see the wall's test above) leave the
// rest of the spectrum undecided; the verdict does not need it. The discrete lift-off eigenvalue
// lies above the closed form by at most 4h 2 (2 pi)^2 / l^3 (the strut shorter by up to 4h, as
// above; measured 7.4 and 4.1 against bounds 8.9 and 7.8 at 1.03 and 1.06 times the onset).
TEST(StabilityExtendedContact, FlatContactPastItsBucklingIsUnstable) {
  const analytic::FlatContactBuckling onset = analytic::flat_contact_buckling(1.0, 1.0, 0.1);
  std::string text = testing::case_text("cavity.toml");
  const std::string guess = "[guess]\nforce = [\"-P_guess\", 0]\nmoment = [0, 0, \"m_guess\"]\n";
  ASSERT_NE(text.find(guess), std::string::npos);
  const double edge_force = onset.P * std::tan(onset.alpha);  // the outer arcs' line of force
  std::ostringstream flat;
  flat << std::setprecision(17) << "[guess]\nforce = [" << -onset.P << ", " << -edge_force
       << "]\nmoment = [0, 0, 0]\n\n[[guess.contacts]]\nobstacle = \"upper wall\"\ns = " << onset.contact_start
       << "\ns_end = " << 1.0 - onset.contact_start << "\nforce = " << edge_force << "\nforce_end = " << edge_force
       << "\n";
  text.replace(text.find(guess), guess.size(), flat.str());
  for (double beyond : {1.03, 1.06}) {
    SCOPED_TRACE("Delta = " + std::to_string(beyond) + " times the onset");
    CaseSolveOptions options;
    options.direct = true;
    options.solution = options.stability = options.stability_check = false;
    // Newton converges only linearly here (the clamps parallel to the wall: contact.cpp's
    // stalled_flat_contact_reason) and may stall at 2.5e-12: the tolerance a decade looser, as
    // the solver's message advises.
    const CaseSolve s = solve_case(
        load_case_text(text, "cavity_flat", {{"Delta", beyond * onset.Delta}}, "", {{"tolerance", "1e-11"}}), options);
    ASSERT_TRUE(s.converged()) << s.message << s.summary().brief_report();
    const ShootingProblem& problem = *s.solved.problem;
    const Eigen::VectorXd& x = s.solved.result.x;
    const PointContact c = extended_contact(s);
    const double l = c.s_end - c.s, P = -problem.sample(x, {0.0}).front().n.x();
    const double closed = std::pow(2 * kPi / l, 2) - P, h = 1.0 / kDiscreteStabilityLyingElements;
    ASSERT_LT(closed, 0.0);
    const DiscreteStability d = discrete_stability(problem, x);
    EXPECT_GE(d.lift_off_eigenvalue, closed);
    EXPECT_LE(d.lift_off_eigenvalue, closed + 4 * h * 2 * std::pow(2 * kPi, 2) / std::pow(l, 3));
    EXPECT_TRUE(d.unstable) << d.reason;
    const StabilityReport report = analyse_stability(problem, x);
    EXPECT_FALSE(report.defined());
    EXPECT_TRUE(report.unstable);
    EXPECT_NE(report.reason.find("unstable: the part lying on the obstacle"), std::string::npos) << report.reason;
    EXPECT_EQ(stability_json(report, nullptr)["stable"], false);
    EXPECT_NE(describe(report).find("unstable, no index"), std::string::npos);
  }
}

}  // namespace
}  // namespace kirchhoff
