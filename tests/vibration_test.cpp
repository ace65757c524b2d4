// Small-amplitude vibrations about planar equilibria (section 9, eqs. B.4, 95b, 96, 97): numeric
// frequencies against the closed forms of straight columns and beams, the invariant H_vib, and
// vibrations about the buckled Elastica.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/analysis/vibration.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// The frequencies come from a determinant of solutions integrated at 1e-12 per step over a
// half rod; the solutions of the highest modes tested grow like exp(sqrt(omega) L / 2) ~ 1e2 there,
// which bounds the determinant's relative error, and so its simple roots', by ~1e-10. 1e-9 leaves a
// margin of 10 on that bound; measured errors are 4e-14 to 1.4e-12.
constexpr double kFrequencyTolerance = 1e-9;
// H_vib is a sum of terms integrated to ~1e-10 relative; a flat invariant varies by less than this
// relative to its largest term.
constexpr double kFlatTolerance = 1e-9;

using analytic::BeamEnds;

// A straight uniform planar rod along e_x, EI = 1, length L, with the given ends; the internal
// force is -P e_x (P the compressive load at the ends, 0 for a cantilever).
struct StraightRod {
  std::unique_ptr<ShootingProblem> problem;
  Eigen::VectorXd x;
};

StraightRod straight_rod(EndCondition start, EndCondition end, double P, double L = 1.0) {
  ProblemDefinition d;
  d.kind = RodKind::Planar;
  d.model = [L](const Parameters&) {
    RodModel m;
    m.length = L;
    return m;
  };
  d.start = std::move(start);
  d.end = std::move(end);
  StraightRod out;
  out.problem = std::make_unique<ShootingProblem>(d);
  RodPoint guess;
  guess.R = planar_reference_frame();
  guess.n = Vec3(-P, 0.0, 0.0);
  ShootingResult r = solve(*out.problem, out.problem->initial_unknowns(guess));
  EXPECT_TRUE(r.summary.converged()) << r.summary.brief_report();
  out.x = r.x;
  return out;
}

VectorTarget axial_load(double P) { return constant(Vec3(-P, 0.0, 0.0)); }
OrientationFunction along_x() { return constant_orientation(OrientationTarget{Vec3::UnitZ(), 0.0}); }

double relative_error(double numeric, double exact) { return std::abs(numeric - exact) / std::abs(exact); }

// Pinned column whose far end slides along x under the dead load P (euler_column.toml, straight).
testing::Solved straight_euler_column(double P) {
  return testing::solve_case("euler_column.toml", {{"P", P}, {"theta_guess", 0.0}});
}

TEST(Analytic, BeamFrequencyParameters) {
  EXPECT_NEAR(analytic::beam_frequency_parameter(BeamEnds::ClampedFree, 1), 1.87510406871196, 1e-13);
  EXPECT_NEAR(analytic::beam_frequency_parameter(BeamEnds::ClampedFree, 2), 4.69409113297418, 1e-13);
  EXPECT_NEAR(analytic::beam_frequency_parameter(BeamEnds::ClampedClamped, 1), 4.73004074486270, 1e-13);
  EXPECT_NEAR(analytic::beam_frequency_parameter(BeamEnds::ClampedClamped, 2), 7.85320462409584, 1e-13);
  // The clamped column's characteristic equation at P = 0 is the clamped-clamped beam's.
  EXPECT_NEAR(analytic::clamped_column_frequency(1.0, 0.0, 1.0, 1.0, 2),
              analytic::beam_frequency(BeamEnds::ClampedClamped, 1.0, 1.0, 1.0, 2), 1e-10);
  EXPECT_THROW(analytic::pinned_column_frequency(1.0, 10.0, 1.0, 1.0, 1), std::invalid_argument);  // P > pi^2
  EXPECT_THROW(analytic::beam_frequency_parameter(BeamEnds::ClampedFree, 0), std::invalid_argument);
}

TEST(Vibration, PinnedColumnUnderDeadLoadMatchesEq96) {
  const double P = 0.5 * M_PI * M_PI;
  const auto column = straight_euler_column(P);
  VibrationOptions options;
  options.modes = 3;
  const VibrationProblem vib(*column.problem, column.solution.result.x, options);
  EXPECT_TRUE(vib.straight_equilibrium());
  EXPECT_FALSE(vib.axial_indeterminate());  // the sliding end carries the dead load: nbar_x = 0 there
  const auto omegas = vib.frequencies();
  ASSERT_EQ(omegas.size(), 3u);
  for (int k = 1; k <= 3; ++k)
    EXPECT_LE(relative_error(omegas[k - 1], analytic::pinned_column_frequency(1.0, P, 1.0, 1.0, k)),
              kFrequencyTolerance)
        << "mode " << k;
}

TEST(Vibration, MassPerLengthScalesFrequencies) {
  const auto column = straight_euler_column(2.0);
  VibrationOptions options;
  options.modes = 2;
  options.rho_s = 4.0;
  const auto omegas = VibrationProblem(*column.problem, column.solution.result.x, options).frequencies();
  for (int k = 1; k <= 2; ++k)
    EXPECT_LE(relative_error(omegas[k - 1], analytic::pinned_column_frequency(1.0, 2.0, 4.0, 1.0, k)),
              kFrequencyTolerance);
}

TEST(Vibration, CantileverMatchesBeamTheory) {
  const double L = 2.0;
  const auto rod = straight_rod(EndCondition::clamped(constant(Vec3::Zero()), along_x()), EndCondition::free(), 0.0, L);
  VibrationOptions options;
  options.modes = 3;
  const auto omegas = VibrationProblem(*rod.problem, rod.x, options).frequencies();
  for (int k = 1; k <= 3; ++k)
    EXPECT_LE(relative_error(omegas[k - 1], analytic::beam_frequency(BeamEnds::ClampedFree, 1.0, 1.0, L, k)),
              kFrequencyTolerance)
        << "mode " << k;
}

TEST(Vibration, ClampedClampedBeamIsSolvedDespiteTheAxialIndeterminacy) {
  // Both ends fixed in position: a constant axial force perturbation solves (B.4) for every
  // omega, and the full determinant vanishes identically. The transverse problem is solved.
  const auto rod = straight_rod(EndCondition::clamped(constant(Vec3::Zero()), along_x()),
                                EndCondition::clamped(constant(Vec3(1.0, 0.0, 0.0)), along_x()), 0.0);
  VibrationOptions options;
  options.modes = 3;
  const VibrationProblem vib(*rod.problem, rod.x, options);
  EXPECT_TRUE(vib.axial_indeterminate());
  const auto omegas = vib.frequencies();
  for (int k = 1; k <= 3; ++k)
    EXPECT_LE(relative_error(omegas[k - 1], analytic::beam_frequency(BeamEnds::ClampedClamped, 1.0, 1.0, 1.0, k)),
              kFrequencyTolerance)
        << "mode " << k;
}

TEST(Vibration, ClampedColumnUnderLoadMatchesCharacteristicEquation) {
  for (double P : {-20.0, 15.0, 30.0}) {  // a tension, then compressions below 4 pi^2
    const auto rod = straight_rod(
        EndCondition::clamped(constant(Vec3::Zero()), along_x()),
        EndCondition::sliding(Vec3::UnitX(), constant(Vec3::Zero()), axial_load(P), along_x()), P);
    VibrationOptions options;
    options.modes = 2;
    const auto omegas = VibrationProblem(*rod.problem, rod.x, options).frequencies();
    for (int k = 1; k <= 2; ++k)
      EXPECT_LE(relative_error(omegas[k - 1], analytic::clamped_column_frequency(1.0, P, 1.0, 1.0, k)),
                kFrequencyTolerance)
          << "P = " << P << ", mode " << k;
  }
}

TEST(Vibration, HvibIsFlatAlongModesOfAStraightColumnAndEq97EqualsEq95b) {
  const double P = 0.5 * M_PI * M_PI;
  const auto column = straight_euler_column(P);
  VibrationOptions options;
  options.modes = 3;
  const VibrationAnalysis analysis = VibrationProblem(*column.problem, column.solution.result.x, options).analyse();
  for (const auto& mode : analysis.modes) {
    EXPECT_TRUE(mode.H_vib_stats.applies);
    EXPECT_GT(mode.H_vib_stats.scale, 0.0);
    EXPECT_LE(mode.H_vib_stats.relative_spread(), kFlatTolerance) << "omega = " << mode.omega;
    ASSERT_EQ(mode.H_vib_column.size(), mode.H_vib.size());
    double largest_difference = 0.0, printed_min = INFINITY, printed_max = -INFINITY;
    for (size_t i = 0; i < mode.H_vib.size(); ++i) {
      largest_difference = std::max(largest_difference, std::abs(mode.H_vib_column[i] - mode.H_vib[i]));
      // Eq. (97) as printed (-P w^2 / 2 instead of -P w'^2 / 2) is not an invariant.
      const VibrationState& q = mode.state[i];
      const double printed =
          eq97_hamiltonian(1.0, 1.0, mode.omega, P, {q[1], q[2], q[5], (-q[4] - P * q[2])}, /*as_printed=*/true);
      printed_min = std::min(printed_min, printed);
      printed_max = std::max(printed_max, printed);
    }
    EXPECT_LE(largest_difference, kFlatTolerance * mode.H_vib_stats.scale);
    EXPECT_GT(printed_max - printed_min, 1e-2 * mode.H_vib_stats.scale);
    // The mode is sin(k pi s): ybar(L/2) = +-1 or 0, and the axial components vanish.
    for (const auto& q : mode.state) EXPECT_LE(std::abs(q[0]) + std::abs(q[3]), 1e-12);
  }
}

TEST(Vibration, FirstFrequencyVanishesLinearlyAtTheEulerLoad) {
  // omega_1^2 = pi^2 (pi^2 - P) for EI = L = rhoS = 1: linear in P, zero at the Euler load.
  std::vector<double> loads{1.0, 5.0, 9.0, 9.8};
  std::vector<double> omega2;
  for (double P : loads) {
    const auto column = straight_euler_column(P);
    VibrationOptions options;
    options.modes = 1;
    const double w = VibrationProblem(*column.problem, column.solution.result.x, options).frequencies()[0];
    omega2.push_back(w * w);
  }
  // Fitted line through the first and last point; the others lie on it.
  const double slope = (omega2.back() - omega2.front()) / (loads.back() - loads.front());
  const double zero_at = loads.front() - omega2.front() / slope;
  EXPECT_NEAR(slope, -M_PI * M_PI, 1e-7);
  EXPECT_NEAR(zero_at, M_PI * M_PI, 1e-8);
  for (size_t i = 1; i + 1 < loads.size(); ++i)
    EXPECT_NEAR(omega2[i], omega2.front() + slope * (loads[i] - loads.front()), 1e-7);
}

TEST(Vibration, BuckledElasticaHasFiniteFrequenciesAndHvibIsNotInvariant) {
  // simply_supported.toml: pinned, the far end rolling along x under the dead load P that the
  // imposed end slope theta0 selects.
  const auto buckled = testing::solve_case("simply_supported.toml", {{"theta0", 1.0}});
  VibrationOptions options;
  options.modes = 3;
  const VibrationProblem vib(*buckled.problem, buckled.solution.result.x, options);
  EXPECT_FALSE(vib.straight_equilibrium());
  const VibrationAnalysis analysis = vib.analyse();
  ASSERT_EQ(analysis.modes.size(), 3u);
  for (const auto& mode : analysis.modes) {
    EXPECT_TRUE(std::isfinite(mode.omega));
    EXPECT_GT(mode.omega, 0.0);
    EXPECT_LE(mode.matching_residual, 1e-8);
    EXPECT_FALSE(mode.H_vib_stats.applies);
    EXPECT_TRUE(mode.H_vib_column.empty());
    // theta_e' != 0: the Lagrangian depends on s through theta_e(s) and H_vib varies.
    EXPECT_GT(mode.H_vib_stats.relative_spread(), 1e-3) << "omega = " << mode.omega;
  }
  EXPECT_EQ(analysis.H_vib_not_conserved, "the equilibrium is curved (theta_e varies)");
}

// Straight equilibria on which H_vib still varies, for another reason than a curved rod (the
// table and JSON said "theta_e varies" on them): the tapered column (EI(s)), and a column standing
// under its own weight (its axial force varies along it). The uniform column has it conserved.
TEST(Vibration, SaysWhyHvibVariesOnAStraightEquilibrium) {
  const std::string heavy_column = R"(model = "planar"
[parameters]
w = 5.0
[rod]
length = 1.0
B = 1.0
gravity = { weight = "w", up = [1, 0, 0] }
[start]
type = "clamped"
position = [0, 0]
[end]
type = "free"
[guess]
force = ["w", 0]
)";
  auto heavy = [&heavy_column] {
    testing::Solved out;
    out.c = load_case_text(heavy_column, "heavy_column.toml");
    out.problem = std::make_unique<ShootingProblem>(out.c.definition);
    ShootingResult r = solve(*out.problem, out.problem->initial_unknowns(out.c.start_guess));
    EXPECT_TRUE(r.summary.converged()) << r.summary.brief_report();
    out.solution = make_solution(*out.problem, std::move(r), 101, {});
    return out;
  };
  std::vector<std::pair<testing::Solved, std::string>> cases;
  cases.emplace_back(testing::solve_case("tapered_column.toml", {{"P", 1.0}}), "the rod's properties vary along it");
  cases.emplace_back(heavy(), "an external field acts (the axial force varies)");
  cases.emplace_back(straight_euler_column(5.0), "");
  for (const auto& [solved, reason] : cases) {
    VibrationOptions options;
    options.modes = 1;
    const VibrationProblem vib(*solved.problem, solved.solution.result.x, options);
    ASSERT_TRUE(vib.straight_equilibrium()) << reason;
    const VibrationAnalysis analysis = vib.analyse();
    EXPECT_EQ(analysis.H_vib_not_conserved, reason);
    ASSERT_EQ(analysis.modes.size(), 1u);
    EXPECT_EQ(analysis.modes[0].H_vib_stats.applies, reason.empty()) << reason;
  }
}

TEST(Vibration, BuckledElasticaFirstFrequencyVanishesAtTheBifurcation) {
  // Under the dead load the pitchfork at P = pi^2 is supercritical: the buckled branch is stable
  // and its softest mode softens to zero as the buckle shrinks. The exchange of stability at a
  // symmetric pitchfork predicts omega_1^2 = 2 pi^2 (P - pi^2) (1 + O(theta0^2)): twice the
  // straight column's slope, pi^2 (pi^2 - P), with the sign changed. Measured: the relative
  // deviation is 0.106, 0.029, 0.0075, 0.0019 at theta0 = 0.4, 0.2, 0.1, 0.05 (0.66 theta0^2 to
  // 0.76 theta0^2), so 0.8 theta0^2 bounds it and still fails if the slope were off by a percent.
  double previous = INFINITY;
  for (double theta0 : {0.4, 0.2, 0.1, 0.05}) {
    const auto buckled = testing::solve_case("simply_supported.toml", {{"theta0", theta0}, {"P", 10.0}});
    const double P = buckled.solution.derived.at("P");
    VibrationOptions options;
    options.modes = 1;
    const double w = VibrationProblem(*buckled.problem, buckled.solution.result.x, options).frequencies()[0];
    EXPECT_LT(w, previous);
    previous = w;
    const double slope_ratio = w * w / (2.0 * M_PI * M_PI * (P - M_PI * M_PI));
    EXPECT_LE(std::abs(slope_ratio - 1.0), 0.8 * theta0 * theta0) << "theta0 = " << theta0 << ", P = " << P;
  }
  EXPECT_LT(previous, 0.25);  // omega_1 = 0.2465 at theta0 = 0.05 (P - pi^2 = 3.1e-3)
}

TEST(Vibration, BuckledElasticaWithImposedChordDoesNotSoften) {
  // Both ends pinned at the buckled Elastica's chord (imposed end shortening instead of a dead
  // load): the softening mode moves the chord to first order (xbar(L) = -int thetabar sin theta_e),
  // so the supports forbid it, and as theta0 -> 0 the frequencies tend to those of the straight
  // column at P = pi^2 without its first mode: omega_{k+1} = sqrt((k pi)^4 - pi^2 (k pi)^2),
  // k = 2, 3, 4. Measured deviations are 0.3 theta0^2 relative.
  for (double theta0 : {0.05, 0.01}) {
    const analytic::PinnedElastica exact{1.0, 1.0, theta0};
    auto pinned_at = [](double x) { return EndCondition::pinned(constant(Vec3(x, 0.0, 0.0))); };
    ProblemDefinition d;
    d.kind = RodKind::Planar;
    d.model = [](const Parameters&) { return RodModel{}; };
    d.start = pinned_at(0.0);
    d.end = pinned_at(exact.end_to_end());
    const ShootingProblem problem(d);
    RodPoint guess;
    guess.R = Eigen::AngleAxisd(theta0, Vec3::UnitZ()).toRotationMatrix() * planar_reference_frame();
    guess.n = Vec3(-exact.load(), 0.0, 0.0);
    const ShootingResult r = solve(problem, problem.initial_unknowns(guess));
    ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
    ASSERT_NEAR(r.x[2], theta0, 1e-9);  // the buckled equilibrium, not the straight one
    VibrationOptions options;
    options.modes = 3;
    const VibrationProblem vib(problem, r.x, options);
    EXPECT_FALSE(vib.axial_indeterminate());
    const auto omegas = vib.frequencies();
    for (int k = 2; k <= 4; ++k) {
      const double limit = analytic::pinned_column_frequency(1.0, M_PI * M_PI, 1.0, 1.0, k);
      EXPECT_LE(std::abs(omegas[k - 2] / limit - 1.0), theta0 * theta0) << "theta0 = " << theta0 << ", k = " << k;
    }
  }
}

TEST(Vibration, MultipleShootingGivesTheSameFrequencies) {
  // The equilibrium restarts from the shooting nodes; the frequencies must not depend on how many.
  std::vector<std::vector<double>> by_segments;
  for (int segments : {1, 4}) {
    Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.0}});
    c.definition.options.segments = segments;
    const ShootingProblem problem(c.definition);
    const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
    ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
    VibrationOptions options;
    options.modes = 3;
    by_segments.push_back(VibrationProblem(problem, r.x, options).frequencies());
  }
  for (int k = 0; k < 3; ++k) EXPECT_LE(relative_error(by_segments[1][k], by_segments[0][k]), kFrequencyTolerance);
}

TEST(Vibration, RefusesWhatItDoesNotModel) {
  const auto twisted = testing::solve_case("twisted_clamped.toml", {{"phi", 1.0}});
  EXPECT_THROW(VibrationProblem(*twisted.problem, twisted.solution.result.x), std::invalid_argument);
  const auto column = straight_euler_column(1.0);
  VibrationOptions bad;
  bad.rho_s = -1.0;
  EXPECT_THROW(VibrationProblem(*column.problem, column.solution.result.x, bad), std::invalid_argument);
  VibrationOptions short_grid;
  short_grid.modes = 5;
  short_grid.omega_max = 50.0;  // the 5th frequency is near 25 pi^2 = 247
  const VibrationProblem vib(*column.problem, column.solution.result.x, short_grid);
  EXPECT_THROW(vib.frequencies(), std::invalid_argument);
}

// Unstable equilibria: omega^2 = -sigma^2 < 0. The straight pinned column under the dead load P has
// omega_k^2 = (k pi)^2 ((k pi)^2 - P) / rhoS (eq. 96 for every P), negative for the k with
// (k pi)^2 < P: at P = 50, k = 1 and 2 (-396.07 and -415.38, 0.48 apart in sigma, beyond the grid's
// 0.2).
TEST(Vibration, StraightColumnAtP50HasExactlyTwoNegativeOmega2) {
  const double P = 50.0;
  const auto column = straight_euler_column(P);
  VibrationOptions options;
  options.modes = 1;
  const VibrationProblem vib(*column.problem, column.solution.result.x, options);
  const VibrationAnalysis analysis = vib.analyse();
  ASSERT_EQ(analysis.negative_omega2_count(), 2);
  std::vector<double> exact;
  for (int k = 1; k <= 2; ++k) exact.push_back(std::pow(k * M_PI, 2) * (std::pow(k * M_PI, 2) - P));
  std::sort(exact.begin(), exact.end());
  for (int k = 0; k < 2; ++k) {
    const VibrationMode& mode = analysis.unstable_modes[k];
    EXPECT_LE(relative_error(mode.omega2, exact[k]), kFrequencyTolerance) << "mode " << k;
    EXPECT_EQ(mode.omega, 0.0);
    EXPECT_NEAR(mode.growth_rate(), std::sqrt(-exact[k]), kFrequencyTolerance * std::sqrt(-exact[k]));
    EXPECT_LE(mode.matching_residual, 1e-8);
    // The straight column's H_vib (eq. 95b, and eq. 97) stays invariant with omega^2 < 0.
    EXPECT_TRUE(mode.H_vib_stats.applies);
    EXPECT_LE(mode.H_vib_stats.relative_spread(), kFlatTolerance);
  }
  // The positive frequencies are unchanged: the next one is k = 3.
  EXPECT_LE(relative_error(analysis.modes[0].omega2, std::pow(3 * M_PI, 2) * (std::pow(3 * M_PI, 2) - P)),
            kFrequencyTolerance);
  EXPECT_EQ(analysis.omega2().size(), 3u);
  EXPECT_LT(analysis.omega2()[0], analysis.omega2()[1]);
  // The search reached beyond the most negative: the bound sigma^2 >= P^2 / 4 of a uniform straight
  // column (the infimum of k^2 (k^2 - P) over all wave numbers), and twice further.
  EXPECT_GE(vib.sigma_bound(), 0.5 * P);
  EXPECT_DOUBLE_EQ(vib.sigma_max(), 2 * vib.sigma_bound());
}

// Two negative omega^2 closer than the grid step: near P = 5 pi^2 the straight column's growth
// rates for k = 1 and 2, sqrt(P (k pi)^2 - (k pi)^4), meet (at 5 pi^2 both are 2 pi^2). At P =
// 49.3 they are 19.7272 and 19.6911, 0.036 apart on a step of 0.2: the determinant kept its sign
// at every sample and `vibrate` said "no mode with omega^2 < 0" where `solve` says index 2 (a
// probe). The dip of the determinant between them is now searched: a sign change at its minimum
// splits the pair, a matching matrix of nullity 2 there is the double root.
TEST(Vibration, NegativeOmega2CloserThanTheGridStepAreBothFound) {
  for (const double P : {49.3, 49.34, 5 * M_PI * M_PI, 49.36}) {
    SCOPED_TRACE(P);
    const auto column = straight_euler_column(P);
    VibrationOptions options;
    options.modes = 1;
    const VibrationProblem vib(*column.problem, column.solution.result.x, options);
    const std::vector<double> found = vib.negative_omega2();
    ASSERT_EQ(found.size(), 2u);
    std::vector<double> exact;
    for (int k = 1; k <= 2; ++k) exact.push_back(std::pow(k * M_PI, 2) * (std::pow(k * M_PI, 2) - P));
    std::sort(exact.begin(), exact.end());
    // A simple root to the frequencies' tolerance; the double root is the dip's minimum, located
    // to 1.5e-8 in sigma (Brent's precision in double), so to about 3e-8 in omega^2.
    const bool double_root = P == 5 * M_PI * M_PI;
    for (int k = 0; k < 2; ++k)
      EXPECT_LE(relative_error(found[k], exact[k]), double_root ? 1e-7 : kFrequencyTolerance) << "mode " << k;
  }
}

TEST(Vibration, StableBuckledColumnHasNoNegativeOmega2) {
  const auto buckled = testing::solve_case("euler_column.toml", {{"P", 12.0}, {"theta_guess", 1.0}});
  VibrationOptions options;
  options.modes = 1;
  const VibrationProblem vib(*buckled.problem, buckled.solution.result.x, options);
  EXPECT_FALSE(vib.straight_equilibrium());
  EXPECT_GT(vib.sigma_max(), 0.0);  // it is compressed: the search was made
  EXPECT_TRUE(vib.negative_omega2().empty());
}

// A rod under tension only, without field gradient, cannot have omega^2 < 0: nothing is searched.
TEST(Vibration, RodUnderTensionSearchesNoGrowthRates) {
  const auto hanging = testing::solve_case("heavy_cantilever.toml");
  const VibrationProblem vib(*hanging.problem, hanging.solution.result.x);
  EXPECT_EQ(vib.sigma_max(), 0.0);
  EXPECT_TRUE(vib.negative_omega2().empty());
}

struct IndexRow {
  std::string label, case_name;
  ParameterOverrides overrides;
  int index;  // known: Euler loads, the issue's acceptance list, and stability_test.cpp
  bool homotopy = false;  // solved as `solve` does (from the file's values), not from the guess
};

// By Sylvester's law of inertia the number of negative omega^2 is the index of the second
// variation. On these cases the vibration problem and stability.hpp read the ends alike (no
// unknown end load), so the count equals analyse_stability's index.
TEST(Vibration, NegativeOmega2CountEqualsTheStabilityIndex) {
  const std::vector<IndexRow> rows = {
      {"straight column P = 5", "euler_column.toml", {{"P", 5.0}, {"theta_guess", 0.0}}, 0},
      {"straight column P = 20", "euler_column.toml", {{"P", 20.0}, {"theta_guess", 0.0}}, 1},
      {"straight column P = 100", "euler_column.toml", {{"P", 100.0}, {"theta_guess", 0.0}}, 3},
      {"buckled mode 1 P = 12", "euler_column.toml", {{"P", 12.0}, {"theta_guess", 1.0}}, 0},
      {"mode 1 past the ends meeting P = 30", "euler_column.toml", {{"P", 30.0}, {"theta_guess", 2.5}}, 1},
      {"buckled mode 2 P = 50", "euler_column.toml", {{"P", 50.0}, {"theta_guess", 1.0}}, 1},
      {"buckled mode 3 P = 100", "euler_column.toml", {{"P", 100.0}, {"theta_guess", 1.5}}, 2},
      {"clamped-clamped symmetric", "clamped_clamped.toml", {}, 0},
      {"clamped-clamped S-shaped", "clamped_clamped.toml", {{"s_mode", 1.0}}, 1},
      {"heavy_cantilever", "heavy_cantilever.toml", {}, 0},
      {"tapered_column P = 20", "tapered_column.toml", {{"P", 20.0}}, 1},
      {"tapered_column P = 60", "tapered_column.toml", {{"P", 60.0}}, 2},
      {"shallow_arch", "shallow_arch.toml", {}, 0},
      {"shallow_arch w = 40", "shallow_arch.toml", {{"w", 40.0}}, 1},
      // A stiff barrier: growth rates of 1e3 made the matching matrix near singular across whole
      // dips of its determinant, read as double roots (8 negative omega^2 at log_b = -3, index 0;
      // a probe's discretised energy, 400 elements, has none; at log_b = -2 it has one, -1644.2).
      // (Reached as `solve` reaches them, from the file's values: homotopy.)
      {"soft wall log_b = -3", "soft_wall.toml", {{"log_b", -3.0}, {"Delta", 0.026}}, 0, true},
      {"soft wall log_b = -2.5", "soft_wall.toml", {{"log_b", -2.5}, {"Delta", 0.026}}, 0, true},
      {"soft wall log_b = -2", "soft_wall.toml", {{"log_b", -2.0}, {"Delta", 0.04}}, 1, true},
  };
  VibrationOptions options;
  options.modes = 1;
  for (const IndexRow& row : rows) {
    SCOPED_TRACE(row.label);
    std::unique_ptr<ShootingProblem> problem;
    Eigen::VectorXd x;
    if (row.homotopy) {
      CaseSolve solved = kirchhoff::solve_case(load_case(testing::case_path(row.case_name), row.overrides));
      ASSERT_TRUE(solved.converged()) << solved.message;
      problem = std::move(solved.solved.problem);
      x = solved.solved.result.x;
    } else {
      auto solved = testing::solve_case(row.case_name, row.overrides);
      problem = std::move(solved.problem);
      x = solved.solution.result.x;
    }
    const StabilityReport report = analyse_stability(*problem, x);
    ASSERT_TRUE(report.defined()) << report.reason;
    const int negative = static_cast<int>(VibrationProblem(*problem, x, options).negative_omega2().size());
    EXPECT_EQ(negative, *report.index);
    EXPECT_EQ(negative, row.index);
  }
}

// simply_supported.toml's P is an unknown end load. stability.hpp reads it as a Lagrange multiplier
// (the end shortening held); the vibration problem keeps the sliding end's load fixed while the rod
// vibrates, a dead load. At theta0 = 1 and 2 both readings give index 0. At theta0 = 2.8 the ends
// meet: with the shortening held the rod can only turn about the shared pin (a zero mode, index 0);
// under the dead load that turn lets the load do work and the rod is unstable, as stability.hpp
// says of the same equilibrium posed with the load given (euler_column.toml at that P).
TEST(Vibration, SimplySupportedLoadIsReadAsADeadLoad) {
  VibrationOptions options;
  options.modes = 1;
  for (const auto& [theta0, dead_index] : std::vector<std::pair<double, int>>{{1.0, 0}, {2.0, 0}, {2.8, 1}}) {
    SCOPED_TRACE("theta0 = " + std::to_string(theta0));
    const auto solved = testing::solve_case("simply_supported.toml", {{"theta0", theta0}});
    const Eigen::VectorXd& x = solved.solution.result.x;
    const int negative = static_cast<int>(VibrationProblem(*solved.problem, x, options).negative_omega2().size());
    EXPECT_EQ(negative, dead_index);
    const StabilityReport multiplier = analyse_stability(*solved.problem, x);
    ASSERT_TRUE(multiplier.defined()) << multiplier.reason;
    EXPECT_EQ(*multiplier.index, 0);
    EXPECT_EQ(multiplier.zero_modes, theta0 > 2.5 ? 1 : 0);
    // The same equilibrium with the load given: the case's definition without the unknown.
    const Case dead = load_case(testing::case_path("euler_column.toml"), {{"P", solved.solution.derived.at("P")}});
    const ShootingProblem dead_problem(dead.definition);
    const Eigen::VectorXd dead_x = x.head(dead_problem.size());  // the state at s = 0, without P
    const StabilityReport dead_report = analyse_stability(dead_problem, dead_x);
    ASSERT_TRUE(dead_report.defined()) << dead_report.reason;
    EXPECT_EQ(*dead_report.index, dead_index);
  }
}

}  // namespace
}  // namespace kirchhoff
