// The equilibria search (equilibria.hpp) and deflated Newton (deflation.hpp): counts, indices and
// energies of coexisting equilibria against closed forms, independent solves and the classical
// results; the CLI's `equilibria` command.
#include "kirchhoff/jobs/equilibria.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/jobs/case_equilibria.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/detail/equilibrium_families.hpp"
#include "foundation_column_case.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

using testing::case_path;

// Every search in these tests has the residual tolerance of its case; the solution's own checks
// passed, so these are what each listed equilibrium must satisfy.
void expect_all_sound(const EquilibriaSearch& s, double tolerance) {
  for (size_t i = 0; i < s.equilibria.size(); ++i) {
    const Equilibrium& e = s.equilibria[i];
    EXPECT_TRUE(e.solution.result.summary.converged()) << i;
    EXPECT_LE(e.solution.result.summary.residual_norm, tolerance) << i;
    if (i > 0) EXPECT_LE(s.equilibria[i - 1].energy, e.energy) << "sorted by energy";
    // Never the same equilibrium twice: pairwise profiles apart by more than the tolerance.
    for (size_t j = 0; j < i; ++j) {
      const Equilibrium& o = s.equilibria[j];
      EXPECT_GT(profile_distance(*o.problem, o.solution.result.x, *e.problem, e.solution.result.x, 1.0), 1e-6)
          << i << " and " << j;
    }
  }
}

EquilibriaSearch search(const std::string& name, const ParameterOverrides& overrides, EquilibriaOptions options = {}) {
  const Case c = load_case(case_path(name), overrides);
  EquilibriaSearch s = find_equilibria(c.definition, c.start_guess, c.derived, c.samples, options);
  for (const auto& e : s.equilibria)
    std::cout << "  E = " << e.energy << "  " << describe(e.stability) << "  contacts " << e.solution.contacts.size()
              << "  (" << e.found_by << ")\n";
  expect_all_sound(s, c.definition.options.newton.residual_tolerance);
  return s;
}

// A cubic with roots 1, 2, 3 in x0 and x1 = x0: deflation from one start must give the three roots,
// each once, and then fail.
class Cubic final : public NonlinearSystem {
 public:
  int size() const override { return 2; }
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, std::string*) const override {
    const double a = x[0];
    *F = Eigen::Vector2d((a - 1) * (a - 2) * (a - 3), x[1] - a);
    if (J) {
      J->resize(2, 2);
      *J << 3 * a * a - 12 * a + 11, 0, -1, 1;
    }
    return true;
  }
};

TEST(Deflation, FindsEachRootOfACubicOnceFromOneStart) {
  const Cubic cubic;
  DeflationOperator deflation(Eigen::Vector2d(1.0, 1.0));
  std::vector<double> found;
  for (int run = 0; run < 4; ++run) {
    Eigen::VectorXd x = Eigen::Vector2d(0.0, 0.0);
    const NewtonSummary s = deflated_newton(cubic, x, deflation);
    if (!s.converged()) break;
    deflation.add_root(x);
    found.push_back(x[0]);
  }
  ASSERT_EQ(found.size(), 3u);
  std::sort(found.begin(), found.end());
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(found[k], k + 1.0, 1e-9);
}

TEST(Deflation, ScaledLogGradientMatchesFiniteDifferences) {
  DeflationOperator d(Eigen::Vector3d(1.0, 50.0, 0.1));
  d.add_root(Eigen::Vector3d(0.1, 20.0, 0.01));
  d.add_root(Eigen::Vector3d(-0.3, -5.0, 0.02));
  const Eigen::Vector3d x(0.2, 3.0, -0.05);
  const Eigen::VectorXd g = d.log_gradient(x);
  for (int j = 0; j < 3; ++j) {
    // Central differences with h = 1e-6 of the scale: error ~ h^2 |f'''| ~ 1e-10 relative.
    const double h = 1e-6 * d.scale()[j];
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[j] = h;
    const double fd = (std::log(d.value(x + e)) - std::log(d.value(x - e))) / (2 * h);
    EXPECT_NEAR(g[j], fd, 1e-7 * (std::abs(fd) + 1.0 / d.scale()[j])) << j;
  }
}

// The pinned-pinned Elastica of n half-waves under P: theta0 from 2 n K(sin(theta0 / 2)) = sqrt(P / EI) L
// (PinnedElastica::load() of one half-wave of length L / n, increasing in theta0: bisection).
double elastica_theta0(double P, double EI, double L, int n) {
  double lo = 1e-6, hi = M_PI - 1e-9;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (analytic::PinnedElastica{L / n, EI, mid}.load() < P ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The Euler column's rods whose ends meet (x(L) = 0), at the dead load P: each is a closed
// mode-k Elastica (k half-waves) under the force |n| = k^2 lambda_1, lambda_1 the load at which the
// mode-1 Elastica's ends meet (theta0 = theta_c, x(L) = 0), turned so that n_x = -P: the lateral
// reaction is +-sqrt(|n|^2 - P^2), and each sign comes with its mirror image, four rods per k
// with k^2 lambda_1 > P (k >= 2 at P = 50, without end).
// Energy: bending only (x(L) = 0), -|n| L cos(theta_c) (H = -|n| cos(theta_c) along the rod and
// the chord along n is zero).
// They are isolated equilibria, not points of a family: turning such a rod by phi about the pin
// keeps its energy and r(L) = 0, but turns its internal force with it, changing the axial end
// force by -n_y phi, which the dead load forbids unless n_y = 0 (the mode-1 rod exactly where its
// ends meet, stability_test.cpp). So no zero mode, and the discretised energy (an independent
// count) agrees: no eigenvalue near zero.
void expect_isolated_rods_whose_ends_meet(const std::vector<const Equilibrium*>& meeting, double P) {
  double lo = 2.0, hi = 2.6;  // x(L) of the mode-1 Elastica changes sign once in between
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (analytic::PinnedElastica{1.0, 1.0, mid}.end_to_end() > 0 ? lo : hi) = mid;
  }
  const double theta_c = 0.5 * (lo + hi), lambda_1 = analytic::PinnedElastica{1.0, 1.0, theta_c}.load();
  ASSERT_GE(meeting.size(), 8u);
  std::map<int, int> count, positive_reaction;
  for (const Equilibrium* e : meeting) {
    const Vec3 n = e->solution.profile.front().n;
    const int k = static_cast<int>(std::lround(std::sqrt(n.norm() / lambda_1)));
    SCOPED_TRACE("closed mode " + std::to_string(k) + ", n_y = " + std::to_string(n.y()));
    ASSERT_GE(k, 2);  // mode 1 closes at lambda_1 = 21.5 < P: no such rod at P = 50
    ++count[k];
    positive_reaction[k] += n.y() > 0;
    EXPECT_LT(e->solution.derived.at("end_to_end"), 1e-9);
    // The closed forms, from the elliptic integrals to ~1e-12: the solve's 1e-8 relative.
    EXPECT_NEAR(n.x(), -P, 1e-8 * P);
    EXPECT_NEAR(n.norm(), k * k * lambda_1, 1e-8 * n.norm());
    EXPECT_NEAR(e->energy, -k * k * lambda_1 * std::cos(theta_c), 1e-8 * e->energy);
    ASSERT_TRUE(e->stability.index) << e->stability.reason;
    EXPECT_EQ(*e->stability.index, k);
    EXPECT_EQ(e->stability.zero_modes, 0);
  }
  // The search stops at --max, so a group may be listed in part; a whole one has two rods
  // of each reaction's sign.
  int whole_groups = 0;
  for (const auto& [k, found] : count) {
    EXPECT_LE(found, 4) << "closed mode " << k;
    if (found == 4) {
      ++whole_groups;
      EXPECT_EQ(positive_reaction[k], 2) << "closed mode " << k;
    }
  }
  EXPECT_GE(whole_groups, 1);
  // The independent count on one rod of each energy (the list is sorted by energy).
  for (const Equilibrium* e : {meeting.front(), meeting.back()}) {
    const DiscreteStability d = discrete_stability(*e->problem, e->solution.result.x);
    ASSERT_TRUE(d.defined()) << d.reason;
    EXPECT_TRUE(d.trustworthy) << d.check_message;
    EXPECT_EQ(d.index, e->stability.index);
    EXPECT_EQ(d.zero_modes, 0);
    // A symmetry would give |mu| ~ 1e-10 (discrete_stability.hpp); measured, the eigenvalue closest
    // to zero is -8.70 (mode 2) and -10.77 (mode 3) B / L^2, equal at N and N / 2 to 1e-4.
    double closest = std::numeric_limits<double>::infinity();
    for (double mu : d.lowest_eigenvalues) closest = std::min(closest, std::abs(mu));
    EXPECT_GT(closest, 1.0);
  }
}

// A spatial cantilever (B1 = 1 < B2 = 1.5, B3 = 0.8) under a dead compressive end load P, its
// file's value 10.
const char* const kSpatialCantilever = R"(
title = "spatial cantilever under a dead compressive end load"
model = "spatial"
[parameters]
P = 10.0
[rod]
length = 1.0
B1 = 1.0
B2 = 1.5
B3 = 0.8
[start]
type = "clamped"
position = [0, 0, 0]
[end]
type = "loaded"
force = [0, 0, "-P"]
moment = [0, 0, 0]
[guess]
force = [0, 0, "-P"]
moment = [0, 0, 0]
)";

// The energy of the cantilever of length L buckled in its first mode in a plane of stiffness B
// under P: half of the pinned Elastica of length 2L under P (its mid-span is the clamp), with
// theta0 from P = 4 K(k)^2 B / (2L)^2; with H = B kappa^2/2 - P cos(theta) = -P cos(theta0) its
// energy is bending P (c - L cos theta0) plus the load's P c, c = half the pinned chord (the tip's
// height).
double buckled_cantilever_energy(double P, double B, double L) {
  double lo = 1e-6, hi = M_PI - 1e-9;  // load(theta0) increases from pi^2 B / (2L)^2 to infinity
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (analytic::PinnedElastica{2 * L, B, mid}.load() < P ? lo : hi) = mid;
  }
  const analytic::PinnedElastica half{2 * L, B, 0.5 * (lo + hi)};
  const double chord = 0.5 * half.end_to_end();
  return P * (2 * chord - L * std::cos(half.theta0));
}

// At P = 10, past its critical loads pi^2/4 B1 = 2.47 and pi^2/4 B2 = 3.70 (and below 9 pi^2/4 B1 =
// 22.2), besides the straight rod (index 2, energy P L) it has the rods buckled in the weak plane
// (stable) and in the stiff plane (index 1), each with its mirror image. The search from the
// straight rod's smallest singular directions alone listed the straight rod only.
TEST(Equilibria, SpatialCantileverListsItsBuckledRodsInBothPlanes) {
  const double P = 10.0, L = 1.0;
  const Case c = load_case_text(kSpatialCantilever, "cantilever.toml");
  const EquilibriaSearch s = find_equilibria(c.definition, c.start_guess, c.derived, c.samples, {});
  ASSERT_EQ(s.equilibria.size(), 5u);
  const double weak = buckled_cantilever_energy(P, 1.0, L), stiff = buckled_cantilever_energy(P, 1.5, L);
  const double expected_energy[5] = {weak, weak, stiff, stiff, P * L};
  const int expected_index[5] = {0, 0, 1, 1, 2};
  for (int k = 0; k < 5; ++k) {
    const Equilibrium& e = s.equilibria[static_cast<size_t>(k)];
    // The solve's residuals at 1e-10 and the elliptic closed forms at ~1e-12: 1e-8 relative.
    EXPECT_NEAR(e.energy, expected_energy[k], 1e-8 * P * L) << k;
    ASSERT_TRUE(e.stability.index) << e.stability.reason;
    EXPECT_EQ(*e.stability.index, expected_index[k]) << k;
    EXPECT_EQ(e.stability.zero_modes, 0) << k;  // B1 != B2: no rotational symmetry
  }
}

// Under P = 30 (12 times its first critical load) the cantilever's stable equilibria are its
// first-mode rods in the weak plane, looped back past the clamp (tip height -0.6346 L, energy
// -8.0926 P L / 30, the global minimum): far from every starting point the search makes at P = 30,
// which listed the second-mode rods and the straight one and missed them ("seeds exhausted"). At
// the file's P = 10 the search finds them beside the straight rod, and each follows the load to 30
// along its homotopy: with P = 30 set, the list starts with them. The search at the requested
// values stops at the four rods the homotopies bring (max_equilibria), which keeps the test short.
TEST(Equilibria, AHeavilyLoadedRodsGlobalMinimumIsCarriedFromTheFilesValues) {
  const double P = 30.0, L = 1.0;
  const Case c = load_case_text(kSpatialCantilever, "cantilever.toml", {{"P", P}});
  EquilibriaOptions options;
  options.max_equilibria = 4;
  const EquilibriaSearch s = find_case_equilibria(c, c.samples, options);
  ASSERT_GE(s.equilibria.size(), 2u);
  const double weak = buckled_cantilever_energy(P, 1.0, L);  // -8.092630080
  int carried = 0;
  for (int k = 0; k < 2; ++k) {
    const Equilibrium& e = s.equilibria[static_cast<size_t>(k)];
    EXPECT_NEAR(e.energy, weak, 1e-8 * P * L) << k;  // as above
    ASSERT_TRUE(e.stability.index) << e.stability.reason;
    EXPECT_EQ(*e.stability.index, 0) << k;
    carried += e.found_by.find("homotopy from the file's values") != std::string::npos;  // the other: its mirror
  }
  EXPECT_GE(carried, 1);
  // The two are mirror images: their tips on either side of the clamp's plane.
  const auto tip = [&](int k) { return s.equilibria[static_cast<size_t>(k)].solution.profile.back().r; };
  EXPECT_NEAR(tip(0).y(), -tip(1).y(), 1e-8);
  EXPECT_GT(std::abs(tip(0).y()), 0.3);
}

TEST(Equilibria, EulerColumnAtP50) {
  const double P = 50.0, EI = 1.0, L = 1.0;
  // 24, not the default 16: every singular direction of a single-shooting problem is a seed, and
  // the first 16 found then hold no whole group of closed rods (checked below).
  EquilibriaOptions options;
  options.max_equilibria = 24;
  const EquilibriaSearch s = search("euler_column.toml", {{"P", P}}, options);
  // Besides the six classical equilibria the dead-load column has rods whose ends meet
  // (x(L) = 0: the roller's lateral reaction then does no moment about the pin, so n_y != 0 is
  // allowed). The six are the ones with the ends apart; the others are checked below.
  std::vector<const Equilibrium*> apart, meeting;
  for (const auto& e : s.equilibria)
    (e.solution.derived.at("end_to_end") > 1e-9 ? apart : meeting).push_back(&e);
  ASSERT_EQ(apart.size(), 6u);
  expect_isolated_rods_whose_ends_meet(meeting, P);
  EXPECT_EQ(s.families, 0);  // all isolated
  // By energy: the straight rod turned against the load (in tension: the global minimum, -P L,
  // and stable, its second variation EI eta'^2 + P eta^2 positive), mode 1 (both mirror images),
  // mode 2 (both), the straight column.
  const Equilibrium& tension = *apart[0];
  EXPECT_NEAR(std::cos(tension.solution.profile.front().turn_angle), -1.0, 1e-9);
  EXPECT_NEAR(tension.energy, -P * L, 1e-9 * P * L);
  ASSERT_TRUE(tension.stability.index);
  EXPECT_EQ(*tension.stability.index, 0);
  EXPECT_EQ(tension.stability.zero_modes, 0);
  const int expected_modes[5] = {1, 1, 2, 2, 0};
  for (int k = 0; k < 5; ++k) {
    const Equilibrium& e = *apart[k + 1];
    const double theta0 = e.solution.profile.front().turn_angle;
    const double x_L = e.solution.profile.back().r.x();
    const int n = expected_modes[k];
    if (n == 0) {
      EXPECT_NEAR(std::sin(theta0), 0.0, 1e-9);
      EXPECT_NEAR(e.energy, P * L, 1e-9 * P * L);  // -F.r(L) = P L, no bending
      ASSERT_TRUE(e.stability.index);
      EXPECT_EQ(*e.stability.index, 2);  // two Euler loads, pi^2 and 4 pi^2, below P
      continue;
    }
    const double closed = elastica_theta0(P, EI, L, n);
    // theta0 up to its sign (the mirror image) and whole turns.
    EXPECT_NEAR(std::cos(theta0), std::cos(closed), 1e-8) << k;
    EXPECT_NEAR(std::abs(std::sin(theta0)), std::sin(closed), 1e-8) << k;
    // Chord: n half-waves of length L / n.
    const analytic::PinnedElastica half_wave{L / n, EI, closed};
    EXPECT_NEAR(x_L, n * half_wave.end_to_end(), 1e-8) << k;
    // H = 1/2 EI theta'^2 - P cos(theta) = -P cos(theta0), so the bending energy is
    // P (x(L) - L cos(theta0)) and the total with the load's P x(L) is 2 P x(L) - P L cos(theta0).
    EXPECT_NEAR(e.energy, 2 * P * x_L - P * L * std::cos(closed), 1e-8 * P * L) << k;
    // Mode 2: index 1 (k - 1). Mode 1: index 1 too, because at P = 50 its ends have crossed
    // (theta0 = 2.906 > 2.2813, docs/stability.md: the ends meeting is a loss of stability).
    ASSERT_TRUE(e.stability.index) << k;
    EXPECT_EQ(*e.stability.index, 1) << k;
  }
}

// Well above the third Euler load the shooting is ill-conditioned (the residual's sensitivity to
// theta0 grows like exp(sqrt(P) L)): at P = 100 the first mode's residual read 3e-10 when
// integrated without sensitivities and the search rejected it, and no seed reached the straight
// rod in tension. Now the list starts with that rod (-P L, stable) and holds each mode k = 1, 2,
// 3 ((k pi)^2 < P) as the closed form gives it, with the discretised energy's index.
TEST(Equilibria, EulerColumnAtP100ListsTheRodInTensionAndEveryMode) {
  const double P = 100.0, EI = 1.0, L = 1.0;
  const EquilibriaSearch s = search("euler_column.toml", {{"P", P}});
  ASSERT_FALSE(s.equilibria.empty());
  const Equilibrium& tension = s.equilibria.front();
  EXPECT_NEAR(std::cos(tension.solution.profile.front().turn_angle), -1.0, 1e-9);
  EXPECT_NEAR(tension.energy, -P * L, 1e-9 * P * L);
  ASSERT_TRUE(tension.stability.index);
  EXPECT_EQ(*tension.stability.index, 0);
  for (int n = 1; n <= 3; ++n) {
    SCOPED_TRACE("mode " + std::to_string(n));
    const double closed = elastica_theta0(P, EI, L, n);
    const auto mode = std::find_if(s.equilibria.begin(), s.equilibria.end(), [&](const Equilibrium& e) {
      const double theta0 = e.solution.profile.front().turn_angle;
      // theta0 up to its sign and whole turns; the solve's 1e-8 (the closed form's ~1e-12).
      return std::abs(std::cos(theta0) - std::cos(closed)) < 1e-8 &&
             std::abs(std::abs(std::sin(theta0)) - std::sin(closed)) < 1e-8;
    });
    ASSERT_NE(mode, s.equilibria.end());
    const DiscreteStability d = discrete_stability(*mode->problem, mode->solution.result.x);
    ASSERT_TRUE(d.defined()) << d.reason;
    ASSERT_TRUE(d.trustworthy) << d.check_message;
    ASSERT_TRUE(mode->stability.index) << mode->stability.reason;
    EXPECT_EQ(mode->stability.index, d.index);
  }
}

// As `kirchhoff equilibria cases/euler_column.toml --set P=100` lists them (find_case_equilibria):
// the first mode's two mirror rods (theta0 = +-3.0876433, energy -20.0145392, index 1), carried
// from the file's P = 12 to residuals of 1.6e-10, were rejected by the residual test and deflated,
// and with them the search's own root: one of the two was missing at every --max.
TEST(Equilibria, EulerColumnSetToP100ListsBothFirstModesAsTheCliDoes) {
  const double P = 100.0, EI = 1.0, L = 1.0;
  const Case c = load_case(case_path("euler_column.toml"), {{"P", P}});
  EquilibriaOptions options;
  options.max_equilibria = 8;
  const EquilibriaSearch s = find_case_equilibria(c, c.samples, options);
  expect_all_sound(s, c.definition.options.newton.residual_tolerance);
  const double closed = elastica_theta0(P, EI, L, 1);
  for (const double side : {1.0, -1.0}) {
    const auto mode = std::find_if(s.equilibria.begin(), s.equilibria.end(), [&](const Equilibrium& e) {
      return std::abs(e.solution.profile.front().turn_angle - side * closed) < 1e-8;  // as above
    });
    ASSERT_NE(mode, s.equilibria.end()) << "theta0 = " << side * closed;
    ASSERT_TRUE(mode->stability.index);
    EXPECT_EQ(*mode->stability.index, 1);
  }
}

TEST(Equilibria, ClampedClampedModesAgreeWithTheirSolvesFromTheCaseGuess) {
  const EquilibriaSearch s = search("clamped_clamped.toml", {});
  // The default search stops at 16 equilibria: the first eight modes.
  ASSERT_EQ(s.equilibria.size(), 16u);
  // Each mode with its mirror image, the index rising by one per mode: symmetric 0, S-shaped 1, ...
  for (int k = 0; k < 16; ++k) {
    ASSERT_TRUE(s.equilibria[k].stability.index) << k;
    EXPECT_EQ(*s.equilibria[k].stability.index, k / 2) << k;
  }
  for (const double s_mode : {0.0, 1.0}) {
    const auto solved = testing::solve_case("clamped_clamped.toml", {{"s_mode", s_mode}});
    const double E = total_potential_energy(*solved.problem, solved.solution.result.x);
    // Both ends held: no load potential, the energy is the elastic energy, which solution.cpp
    // integrates on its own (Simpson on 4000 intervals): both quadratures are ~1e-12 accurate.
    const Solution with = make_solution(*solved.problem, solved.solution.result, 101, {"elastic_energy"});
    EXPECT_NEAR(E, with.derived.at("elastic_energy"), 1e-10 * E);
    const int k = s_mode == 0.0 ? 0 : 2;
    // Newton from the guess converges to 1e-10 in the residual; energies agree to ~1e-9.
    EXPECT_NEAR(s.equilibria[k].energy, E, 1e-8 * E) << s_mode;
    EXPECT_NEAR(s.equilibria[k + 1].energy, E, 1e-8 * E) << s_mode;
  }
}

// A column on a stiff Winkler foundation (k = 1e6) below its first critical load (2000.17): the
// straight rod is the lowest-energy equilibrium, and stable. The conjugate points leave its index
// undefined (the held end's response to its load is below their zero tolerance); the listing
// gives the discretised energy's, as solve does, where it was null.
TEST(Equilibria, TheDiscretisedEnergyDecidesWhereTheConjugatePointsDoNot) {
  const Case c = load_case_text(testing::foundation_column_case(1100.0, 1e6), "foundation.toml");
  EquilibriaOptions options;
  options.max_equilibria = 1;
  const EquilibriaSearch s = find_equilibria(c.definition, c.start_guess, c.derived, c.samples, options);
  ASSERT_EQ(s.equilibria.size(), 1u);
  const StabilityReport& straight = s.equilibria[0].stability;
  ASSERT_TRUE(straight.index) << straight.reason;
  EXPECT_EQ(*straight.index, 0);
  EXPECT_EQ(straight.method, "discretised_energy");
  EXPECT_NE(straight.method_reason.find("degenerate constraint"), std::string::npos) << straight.method_reason;
  // The straight rod's energy: the foundation's weight b at height 0 against the wall at a = 1 gives
  // b / a per length (b = k / 2), and the load's potential P x(L) = P L.
  EXPECT_NEAR(s.equilibria[0].energy, 5e5 + 1100.0, 1e-9 * 5e5);
}

TEST(Equilibria, EnergyOfAHeavyCantileverIsElasticPlusFieldPotential) {
  // A cantilever under its own weight, the far end free: no end load does work, so the total
  // potential energy is the elastic energy plus the weight's potential, which solution.cpp
  // integrates on its own (elastic_energy, E_wall: Simpson on 4000 intervals, ~1e-12).
  const auto solved = testing::solve_case("heavy_cantilever.toml");
  const Solution parts = make_solution(*solved.problem, solved.solution.result, 101, {"elastic_energy", "E_wall"});
  const double E = total_potential_energy(*solved.problem, solved.solution.result.x);
  const double expected = parts.derived.at("elastic_energy") + parts.derived.at("E_wall");
  EXPECT_NEAR(E, expected, 1e-10 * (std::abs(parts.derived.at("elastic_energy")) + std::abs(parts.derived.at("E_wall"))));
  // It sags: the weight's potential is negative and larger than the bending it costs (a minimum).
  EXPECT_LT(parts.derived.at("E_wall"), 0.0);
  EXPECT_LT(E, 0.0);
}

// Complementarity of every listed equilibrium with obstacles.
void expect_admissible(const Equilibrium& e) {
  EXPECT_GE(e.solution.derived.at("min_gap"), -1e-9);
  for (const auto& c : e.solution.contacts) {
    EXPECT_GE(c.force, 0.0);
    if (c.extended) EXPECT_GE(c.force_end, 0.0);
  }
}

// The symmetric point contact at s = 0.5 and its reversal (the rod run from its other end) are
// one equilibrium; solved twice, their contacts came out at 0.5 + 5e-13 and 0.5 - 3e-14, so a
// profile sample at 0.5 read the internal force on opposite sides of the contact's jump (|dn| =
// its force, 43.3) and the same rod was listed twice. Independently of that comparison: no two
// listed rods with the same energy, contact positions and derived values.
TEST(Equilibria, WallListsItsSymmetricContactOnce) {
  const EquilibriaSearch s = search("wall.toml", {{"Delta", 0.028}});
  int symmetric = 0;
  for (size_t i = 0; i < s.equilibria.size(); ++i) {
    const Equilibrium& a = s.equilibria[i];
    expect_admissible(a);
    if (a.solution.contacts.size() == 1 && std::abs(a.solution.contacts[0].s - 0.5) < 1e-8) ++symmetric;
    for (size_t j = 0; j < i; ++j) {
      const Equilibrium& b = s.equilibria[j];
      bool same = std::abs(a.energy - b.energy) <= 1e-9 * (1.0 + std::abs(a.energy)) &&
                  a.solution.contacts.size() == b.solution.contacts.size();
      for (size_t k = 0; same && k < a.solution.contacts.size(); ++k)
        same = std::abs(a.solution.contacts[k].s - b.solution.contacts[k].s) < 1e-8;
      for (const auto& [name, value] : a.solution.derived)
        same = same && std::abs(value - b.solution.derived.at(name)) <= 1e-8 * (1.0 + std::abs(value));
      EXPECT_FALSE(same) << "#" << j + 1 << " and #" << i + 1 << " are one rod (" << b.found_by << ", "
                         << a.found_by << ")";
    }
  }
  EXPECT_EQ(symmetric, 1);
}

// The equilibria of a case at --set values include the one `solve` reports there (reached by
// homotopy from the file's values): at Delta = 0.04 the wall's flat contact, which no seed of the
// search reached from the arch's guess before --max stopped it (the active-set loop from a point
// contact widened by 0.05 L does not settle on [0.3909, 0.6091]). Its P is solve's, 251.69 (the
// same Newton on the same path: to round-off).
TEST(Equilibria, CaseEquilibriaIncludeSolvesEquilibrium) {
  const Case c = load_case(case_path("wall.toml"), {{"Delta", 0.04}});
  const EquilibriaSearch s = find_case_equilibria(c, c.samples);
  expect_all_sound(s, c.definition.options.newton.residual_tolerance * 10);  // (its flat contact: at round-off)
  CaseSolveOptions without_stability;
  without_stability.stability = without_stability.stability_check = false;
  const CaseSolve solved = solve_case(c, without_stability);
  ASSERT_TRUE(solved.converged()) << solved.message;
  const double P = solved.solution->derived.at("P");
  const auto flat = std::find_if(s.equilibria.begin(), s.equilibria.end(), [](const Equilibrium& e) {
    return e.solution.contacts.size() == 1 && e.solution.contacts[0].extended;
  });
  ASSERT_NE(flat, s.equilibria.end());
  EXPECT_NEAR(flat->solution.derived.at("P"), P, 1e-10 * P);
  EXPECT_NEAR(flat->solution.contacts[0].s, 0.3909, 1e-4);
  EXPECT_NE(flat->found_by.find("solve"), std::string::npos) << flat->found_by;
  for (const auto& e : s.equilibria) expect_admissible(e);
}

// The shallow arch (kappa0 = -1, clamped ends 0.9 apart) under w = 150 has one stable
// equilibrium, the arch snapped through and hanging below its chord in tension; the rest (at the
// arch's height, index 2 and 3) are unstable. It is carried from the file's values (w = 0) along
// its homotopy, whose Newton at w = 150 ends at a residual recomputed as 1.7e-9 against the
// tolerance 1e-10 (forces of ~150 integrated to 1e-12 relative): it was dropped there, and the
// search listed no stable equilibrium. Now the search's own root test takes it. Its energy,
// -10.4337, and index 0 (lowest eigenvalue +170) are a discretised energy's at 200 elements (a
// probe's, O(h^2) accurate: 1e-3 relative).
TEST(Equilibria, TheShallowArchSnappedThroughIsListedFarPastItsFold) {
  const Case c = load_case(case_path("shallow_arch.toml"), {{"w", 150.0}});
  const EquilibriaSearch s = find_case_equilibria(c, c.samples);
  const auto hanging = std::find_if(s.equilibria.begin(), s.equilibria.end(), [](const Equilibrium& e) {
    return e.stability.index && *e.stability.index == 0;
  });
  ASSERT_NE(hanging, s.equilibria.end()) << s.log.size();
  EXPECT_NEAR(hanging->energy, -10.4337, 1e-3 * 10.4337);
  EXPECT_NE(hanging->found_by.find("homotopy from the file's values"), std::string::npos) << hanging->found_by;
  // With --max 1 the list is that lowest equilibrium (w = 100: -6.39298 by the same discretised
  // energy): the search at the file's values was cut to one equilibrium, not the one that carries
  // there, and the list held the first known root considered (none at all at w = 100).
  EquilibriaOptions one;
  one.max_equilibria = 1;
  const EquilibriaSearch at_100 = find_case_equilibria(reload_case(c, {{"w", 100.0}}), c.samples, one);
  ASSERT_EQ(at_100.equilibria.size(), 1u);
  EXPECT_NEAR(at_100.equilibria[0].energy, -6.39298, 1e-3 * 6.39298);
  ASSERT_TRUE(at_100.equilibria[0].stability.index);
  EXPECT_EQ(*at_100.equilibria[0].stability.index, 0);
}

// The wall at Delta = 0.05 (a probe's): its hanging fold, the rod touching the wall twice with its
// middle sagging (s = 0.3036 and 0.6964), is stable and lay on no starting point: the search
// made at 0.05 left it out, and its path from the file's Delta = 0.026 turns back at a fold at
// 0.0466 before turning again to reach 0.05. The carried paths now go through folds. Its energy
// and index are a discretised energy's with a barrier b / gap, b -> 1e-8 (the probe's, 1600
// elements: 6.35608, index 0, lowest eigenvalue +51..+61). The symmetric rod touching at
// mid-span (index 1) was missing too: a minimiser held mirror symmetric reaches it (the
// discretised energy at 200 elements: 4.63968, O(h^2), so 1e-3 relative).
TEST(Equilibria, TheWallsHangingFoldAndItsMidSpanContactAreListed) {
  EquilibriaOptions options;
  options.max_equilibria = 40;
  const Case c = load_case(case_path("wall.toml"), {{"Delta", 0.05}});
  const EquilibriaSearch s = find_case_equilibria(c, c.samples, options);  // as `equilibria --set`
  expect_all_sound(s, c.definition.options.newton.residual_tolerance);
  int hanging = 0, mid_span = 0;
  for (const Equilibrium& e : s.equilibria) {
    const auto& c = e.solution.contacts;
    if (c.size() == 2 && !c[0].extended && !c[1].extended && std::abs(c[0].s + c[1].s - 1.0) < 1e-8 &&
        std::abs(std::min(c[0].s, c[1].s) - 0.3036) < 1e-3) {
      ++hanging;
      EXPECT_NEAR(e.energy, 6.35608, 2e-4 * 6.35608);
      ASSERT_TRUE(e.stability.index);
      EXPECT_EQ(*e.stability.index, 0);
    }
    if (c.size() == 1 && !c[0].extended && std::abs(c[0].s - 0.5) < 1e-8 && e.energy < 5.0) {
      ++mid_span;
      EXPECT_NEAR(e.energy, 4.63968, 1e-3 * 4.63968);
      ASSERT_TRUE(e.stability.index);
      EXPECT_EQ(*e.stability.index, 1);
    }
  }
  EXPECT_EQ(hanging, 1);
  EXPECT_EQ(mid_span, 1);
  // With --max 8 the eight equilibria carried from the file's values filled the list and the
  // search stopped before Ipopt's minimisers: neither stable contact (s = 0.3646 and its mirror,
  // energy 3.709783794 by a probe's own shooting) was listed. They are considered whatever --max
  // says, and the 8 lowest kept.
  options.max_equilibria = 8;
  const EquilibriaSearch eight = find_case_equilibria(c, c.samples, options);
  ASSERT_EQ(eight.equilibria.size(), 8u);
  const auto stable_contact = std::find_if(eight.equilibria.begin(), eight.equilibria.end(), [](const Equilibrium& e) {
    return e.solution.contacts.size() == 1 && std::abs(e.energy - 3.709783794) < 1e-8;
  });
  ASSERT_NE(stable_contact, eight.equilibria.end());
  ASSERT_TRUE(stable_contact->stability.index);
  EXPECT_EQ(*stable_contact->stability.index, 0);
}

// --max N holds for the equilibria carried from the file's values and the Ipopt seeds too (the
// wall at Delta = 0.033 listed 5 for --max 3), and the Newton runs count both searches'.
TEST(Equilibria, MaxEquilibriaHoldsWithChangedValues) {
  const Case c = load_case(case_path("wall.toml"), {{"Delta", 0.033}});
  EquilibriaOptions options;
  options.max_equilibria = 3;
  const EquilibriaSearch s = find_case_equilibria(c, c.samples, options);
  EXPECT_EQ(s.equilibria.size(), 3u);
  EXPECT_EQ(s.stopped_because, "max_equilibria reached");
  EXPECT_GT(s.newton_runs, 2);  // (the file's values' search alone made 7)
}

// An end imposed inside an obstacle (the wall's clamps at y = 0 with the wall at y = a = -0.1)
// has no admissible equilibrium: solve says so at once (it reported the fold a homotopy from the
// file's values met on the way, at a = 0.0757), and the search too (it said "seeds exhausted").
TEST(Equilibria, AnEndImposedInsideAnObstacleIsInfeasible) {
  const Case c = load_case(case_path("wall.toml"), {{"a", -0.1}});
  const CaseSolve solved = solve_case(c);
  EXPECT_EQ(solved.failure, "infeasible");
  EXPECT_NE(solved.message.find("inside obstacle 'wall'"), std::string::npos) << solved.message;
  const EquilibriaSearch s = find_case_equilibria(c, c.samples);
  EXPECT_TRUE(s.equilibria.empty());
  EXPECT_EQ(s.stopped_because, "infeasible");
}

TEST(Equilibria, WallNearFlatteningHasSymmetricAndAsymmetricContacts) {
  const EquilibriaSearch s = search("wall.toml", {{"Delta", 0.0307}});
  int symmetric = 0, asymmetric = 0, far = 0, free_down = 0;
  std::vector<double> asymmetric_s;
  for (const auto& e : s.equilibria) {
    expect_admissible(e);
    if (e.solution.contacts.empty()) {
      if (e.stability.stable()) ++free_down;  // buckled away from the wall: the stable free arch
      continue;
    }
    ASSERT_EQ(e.solution.contacts.size(), 1u);
    const PointContact& c = e.solution.contacts.front();
    ASSERT_FALSE(c.extended);
    ASSERT_TRUE(e.stability.index);
    if (std::abs(c.s - 0.5) < 1e-8) {
      ++symmetric;
      EXPECT_EQ(*e.stability.index, 0);  // docs/stability.md: stable up to the flattening
    } else {
      ++asymmetric;
      asymmetric_s.push_back(c.s);
      if (std::abs(c.s - 0.5) > 1e-2) {
        // The far contacts (s = 0.454754 and its mirror, P = 131.24, f = 49.11) are stable: the
        // discretised energy with a sliding contact (discrete_stability) has its lowest
        // eigenvalue at +12.13, +11.91, +11.78 with 200, 400, 800 elements, an independent
        // finite-element second variation (sliding term, chord and contact constraints) +11.70
        // at 2000, and a descent of the discretised obstacle problem from perturbations returns
        // there. The conjugate points give load-controlled index 3 and correction -3 (they gave
        // -2, index 1, while a flat contact went through the rotation frame, whose end loads do
        // not balance a change of the contact force, and the contact's sliding jump missed the
        // multipliers' particular fields: D = dg/dlambda came out unsymmetric and wrong).
        ++far;
        EXPECT_EQ(*e.stability.index, 0) << "s = " << c.s;
      } else {
        // The near-symmetric contacts (s = 0.499225, energy 1.62780782 above the symmetric
        // contact's 1.627807704) sit at the maximum of the energy along the one-contact family
        // between the symmetric contact's minimum and the far contact: index 1 (the barrier-
        // discretised energy of docs/stability.md: -2.57; a descent from it runs to the far one).
        EXPECT_EQ(*e.stability.index, 1) << "s = " << c.s;
      }
    }
  }
  EXPECT_EQ(symmetric, 1);
  EXPECT_EQ(free_down, 1);
  EXPECT_EQ(far, 2);
  // The asymmetric contacts come in mirror pairs s, L - s.
  ASSERT_GE(asymmetric, 4);
  EXPECT_EQ(asymmetric % 2, 0);
  std::sort(asymmetric_s.begin(), asymmetric_s.end());
  for (size_t i = 0; i < asymmetric_s.size(); ++i)
    EXPECT_NEAR(asymmetric_s[i], 1.0 - asymmetric_s[asymmetric_s.size() - 1 - i], 1e-7);
}

TEST(Equilibria, WallBeyondFlatteningHasAFlatContactBesideAsymmetricOnes) {
  const EquilibriaSearch s = search("wall.toml", {{"Delta", 0.033}});
  const Equilibrium* flat = nullptr;
  int asymmetric = 0;
  for (const auto& e : s.equilibria) {
    expect_admissible(e);
    if (e.solution.contacts.size() != 1) continue;
    const PointContact& c = e.solution.contacts.front();
    if (c.extended) {
      flat = &e;
    } else if (std::abs(c.s - 0.5) > 1e-3) {
      ++asymmetric;
      ASSERT_TRUE(e.stability.index);
      // Stable (s = 0.428545, f = 41.77, and its mirror): the discretised energy with a sliding
      // contact has its lowest eigenvalue at +24.65, +24.54, +24.60 with 200, 400, 800 elements.
      // The conjugate points agree since D = dg/dlambda is computed consistently (see above).
      EXPECT_EQ(*e.stability.index, 0) << "s = " << c.s;
    }
  }
  ASSERT_NE(flat, nullptr);
  EXPECT_EQ(asymmetric, 2);
  const PointContact& c = flat->solution.contacts.front();
  // Symmetric about mid-span, and on the flat part H = -P (section 7.2).
  EXPECT_NEAR(c.s + c.s_end, 1.0, 1e-7);
  EXPECT_NEAR(flat->solution.derived.at("H"), -flat->solution.derived.at("P"), 1e-7 * flat->solution.derived.at("P"));
  EXPECT_FALSE(flat->stability.index);  // not defined for extended contacts (docs/stability.md)
  // Deflated roots that penetrate the wall (converged shooting solutions, not equilibria) were
  // met on the way: rejected with the reason, and none of them listed (expect_admissible above).
  // (Others may be rejected on the way too, each with its reason: a root whose residual, made
  // again, is above the tolerance.)
  const auto penetrating = std::count_if(s.rejected.begin(), s.rejected.end(), [](const RejectedPoint& r) {
    return r.reason.find("penetrates") != std::string::npos;
  });
  EXPECT_GE(penetrating, 1);
  for (const auto& r : s.rejected)
    EXPECT_TRUE(r.reason.find("penetrates") != std::string::npos ||
                r.reason.find("residual above the tolerance") != std::string::npos)
        << r.reason;
}

// The wall pushed to Delta = 0.06. The symmetric flat contact over [0.27381, 0.72619] was listed
// three times in the first 24 (fifteen in the first 40): written as a flat part whose forceless
// edge sat at different places with the rest lying on the wall by itself, Newton's roots along
// that continuum 1.7e-6 apart in d3. It is one rod: listed once. And the lowest contact state (one
// point contact at s = 0.34672, force 18.884, stable) was listed without its left-right mirror at
// s = 0.65328, which `solve` reaches from a contact guess there: both are listed.
TEST(Equilibria, WallPushedFurtherListsItsFlatContactOnceAndTheLowestContactWithItsMirror) {
  EquilibriaOptions options;
  options.max_equilibria = 24;
  const EquilibriaSearch s = search("wall.toml", {{"Delta", 0.06}}, options);
  std::vector<double> lowest_contact;
  for (size_t i = 0; i < s.equilibria.size(); ++i) {
    const Equilibrium& a = s.equilibria[i];
    expect_admissible(a);
    for (size_t j = 0; j < i; ++j) {
      const Equilibrium& b = s.equilibria[j];
      // The rods alone, whatever contact sets they are written with; mirror images are far apart.
      EXPECT_GT(profile_distance(*a.problem, a.solution.result.x, *b.problem, b.solution.result.x, 1.0, 101, false),
                1e-3)
          << "#" << j + 1 << " and #" << i + 1 << " are one rod (E = " << a.energy << ")";
    }
    const auto& c = a.solution.contacts;
    if (c.size() == 1 && !c[0].extended && std::abs(c[0].force - 18.884098) < 1e-5) {
      EXPECT_NEAR(a.energy, 4.6681734, 1e-7);
      ASSERT_TRUE(a.stability.index);
      EXPECT_EQ(*a.stability.index, 0);
      lowest_contact.push_back(c[0].s);
    }
  }
  ASSERT_EQ(lowest_contact.size(), 2u);
  EXPECT_NEAR(lowest_contact[0] + lowest_contact[1], 1.0, 1e-8);  // s and L - s
  EXPECT_NEAR(std::min(lowest_contact[0], lowest_contact[1]), 0.3467209, 1e-6);
}

// From the case's own guess (the straight rod) at phi = 10, well below the bifurcation at 11.68
// from which the subcritical buckled rods' branch comes back in phi: only a far kick along the straight rod's low modes reaches the
// buckled rod (its reactions ~4 F0 away), tried once the near seeds are exhausted. Its M and
// end-to-end distance as the continuation of the README's buckled rod from phi = 11.58 down to 10
// gives them (`continue cases/twisted_clamped.toml --set phi=11.58 --set m_lateral=-1.7 --set
// n_lateral=3.4 --phase-condition axial --param phi --to 10`: 6.14925661284, 0.71279840773),
// to the two solves' 1e-8.
TEST(Equilibria, TwistedRodWellBelowItsBifurcationHasTheBuckledRodFoundFromTheStraightGuess) {
  const EquilibriaSearch s = search("twisted_clamped.toml", {{"phi", 10.0}});
  ASSERT_EQ(s.equilibria.size(), 2u) << s.stopped_because;
  EXPECT_EQ(s.stopped_because, "seeds exhausted");
  const Equilibrium& straight = s.equilibria[0];
  EXPECT_NEAR(straight.solution.derived.at("end_to_end"), 1.0, 1e-9);
  ASSERT_TRUE(straight.stability.index);
  EXPECT_EQ(*straight.stability.index, 0);
  const Equilibrium& buckled = s.equilibria[1];
  EXPECT_NEAR(buckled.solution.derived.at("M"), 6.14925661284, 1e-8);
  EXPECT_NEAR(buckled.solution.derived.at("end_to_end"), 0.71279840773, 1e-8);
  ASSERT_TRUE(buckled.stability.index);
  EXPECT_EQ(*buckled.stability.index, 1);
  EXPECT_EQ(buckled.stability.zero_modes, 1);
  EXPECT_NE(buckled.found_by.find("far kick"), std::string::npos) << buckled.found_by;
}

TEST(Equilibria, TwistedRodListsEachCircleOfBuckledRodsOnce) {
  // Below the Greenhill twist (M L / B = 8.9077 < 8.9868) the straight rod is stable and the
  // subcritical buckled rod (index 1) coexists; the isotropic rod's buckled equilibria come in
  // circles about e3 (a zero mode), which Newton reaches anywhere along: each circle listed once.
  const EquilibriaSearch s =
      search("twisted_clamped.toml", {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}});
  ASSERT_GE(s.equilibria.size(), 2u);
  const Equilibrium& straight = s.equilibria[0];
  EXPECT_NEAR(straight.solution.derived.at("end_to_end"), 1.0, 1e-9);
  ASSERT_TRUE(straight.stability.index);
  EXPECT_EQ(*straight.stability.index, 0);
  const Equilibrium& buckled = s.equilibria[1];
  ASSERT_TRUE(buckled.stability.index);
  EXPECT_EQ(*buckled.stability.index, 1);
  EXPECT_EQ(buckled.stability.zero_modes, 1);
  // The README's solve of this equilibrium with the axial phase condition: M = 8.78287684...,
  // end_to_end = 0.97599525...
  EXPECT_NEAR(buckled.solution.derived.at("M"), 8.78287684, 1e-8);
  EXPECT_NEAR(buckled.solution.derived.at("end_to_end"), 0.97599525, 1e-8);
  for (size_t i = 0; i < s.equilibria.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      EXPECT_GT(axial_orbit_distance(*s.equilibria[j].problem, s.equilibria[j].solution.result.x,
                                     *s.equilibria[i].problem, s.equilibria[i].solution.result.x, 1.0),
                1e-6);
}

// A rod pinned at both ends at the same point: both positions held, the reaction a multiplier, so
// turning any equilibrium about the pin gives another (its force turned with it): every closed
// Elastica is a circle of equilibria, each with one zero mode, of which deflation finds several
// points. They are grouped into families, never dropped: within a family the rod is the same up to
// the turn (checked independently of rigid_motion_distance on the tangent angle, theta(s) -
// theta(0)); a rod and its mirror image (the loop run the other way round) are two families.
constexpr const char* kRodPinnedTwiceAtOnePoint = R"(
model = "planar"
[parameters]
F = 86.0
[rod]
length = 1.0
B = 1.0
[start]
type = "pinned"
position = [0, 0]
[end]
type = "pinned"
position = [0, 0]
[guess]
orientation = { axis = [0, 0, 1], angle = 2.2 }
force = ["-F", 0]
)";

TEST(Equilibria, PointsOfOneContinuousFamilyAreGroupedNotCounted) {
  const Case c = load_case_text(kRodPinnedTwiceAtOnePoint, "pinned_twice.toml", {});
  EquilibriaOptions options;
  options.max_equilibria = 8;
  const EquilibriaSearch s = find_equilibria(c.definition, c.start_guess, c.derived, 201, options);
  expect_all_sound(s, c.definition.options.newton.residual_tolerance);
  ASSERT_EQ(s.equilibria.size(), 8u);
  ASSERT_GE(s.families, 2);
  std::vector<int> members(s.families + 1, 0);
  // The tangent angle relative to its start along the rod: what a turn in the plane keeps.
  auto turning = [](const Equilibrium& e) {
    std::vector<double> out;
    for (const RodPoint& p : e.solution.profile) out.push_back(p.turn_angle - e.solution.profile.front().turn_angle);
    return out;
  };
  for (size_t i = 0; i < s.equilibria.size(); ++i) {
    const Equilibrium& e = s.equilibria[i];
    ASSERT_TRUE(e.stability.index) << e.stability.reason;
    EXPECT_EQ(e.stability.zero_modes, 1) << i;
    ASSERT_GE(e.family, 1) << i;
    ASSERT_LE(e.family, s.families) << i;
    ++members[e.family];
    for (size_t j = 0; j < i; ++j) {
      const Equilibrium& o = s.equilibria[j];
      double largest = 0.0;  // max_s of the difference of theta(s) - theta(0)
      const auto a = turning(e), b = turning(o);
      for (size_t k = 0; k < a.size(); ++k) largest = std::max(largest, std::abs(a[k] - b[k]));
      SCOPED_TRACE("#" + std::to_string(i + 1) + " and #" + std::to_string(j + 1));
      // Converged profiles agree to ~1e-9 (equilibria.hpp): 1e-6 for the same rod turned; a rod
      // and its mirror image differ at O(1) (0.1 leaves a wide margin).
      if (e.family == o.family) {
        EXPECT_NEAR(e.energy, o.energy, 1e-10 * e.energy);
        EXPECT_LT(largest, 1e-6);
        EXPECT_LT(rigid_motion_distance(*o.problem, o.solution.result.x, *e.problem, e.solution.result.x, 1.0), 1e-6);
      } else {
        EXPECT_TRUE(std::abs(e.energy - o.energy) > 1e-6 * e.energy || largest > 0.1);
      }
    }
  }
  // Some family was found more than once (the point of grouping): measured, 2 + 2 points of the
  // first closed mode's circle and its mirror image's, 3 + 1 of the second's.
  EXPECT_GE(*std::max_element(members.begin(), members.end()), 2);
  // The independent count: the discretised energy sees the turn about the pin as a zero
  // eigenvalue (~1e-10, discrete_stability.hpp) beside the same index.
  const Equilibrium& first = s.equilibria.front();
  const DiscreteStability d = discrete_stability(*first.problem, first.solution.result.x);
  ASSERT_TRUE(d.defined()) << d.reason;
  EXPECT_TRUE(d.trustworthy) << d.check_message;
  EXPECT_EQ(d.zero_modes, 1);
  EXPECT_EQ(d.index, first.stability.index);
}

int run(const std::string& arguments, const std::string& out) {
  const std::string command = std::string(KIRCHHOFF_CLI) + " " + arguments + " > " + out + " 2>/dev/null";
  return WEXITSTATUS(std::system(command.c_str()));
}

TEST(EquilibriaCli, JsonListsTheModesWithEnergyIndexAndProfiles) {
  const auto dir = std::filesystem::temp_directory_path() / "kirchhoff_equilibria_cli";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string out = (dir / "out.json").string();
  ASSERT_EQ(run("equilibria " + case_path("clamped_clamped.toml") + " --max 4 --json --profiles " +
                    (dir / "profiles").string(),
                out),
            0);
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["equilibria"].size(), 4u);
  const int indices[4] = {0, 0, 1, 1};
  for (int k = 0; k < 4; ++k) {
    const auto& e = j["equilibria"][k];
    EXPECT_EQ(e["status"], "converged");
    EXPECT_EQ(e["rank"], k + 1);
    EXPECT_EQ(e["stability"]["index"], indices[k]);
    EXPECT_EQ(e["isolated"], true);
    EXPECT_TRUE(e["family"].is_null());
    EXPECT_TRUE(e["energy"].is_number());
    EXPECT_TRUE(std::filesystem::exists(dir / "profiles" / ("equilibrium_" + std::to_string(k + 1) + ".csv")));
  }
  EXPECT_EQ(j["stopped_because"], "max_equilibria reached");
  EXPECT_EQ(j["families"], 0);
  // A bad --set is refused as input.
  EXPECT_EQ(run("equilibria " + case_path("clamped_clamped.toml") + " --set nope=1", out), 2);
  // Deflated continuation with a resume is refused (such a run is not resumable), not ignored.
  EXPECT_EQ(run("continue " + case_path("euler_column.toml") + " --param P --to 20 --deflate --resume", out), 2);
}

// Equilibria with zero modes are not isolated: the table says so (index "1 +1 zero", a family
// column, the header's counts, one line per family) and the JSON gives "isolated" and "family".
// The rod pinned twice at one point (PointsOfOneContinuousFamilyAreGroupedNotCounted): its first
// four equilibria lie on two or three circles of closed rods (with Ipopt's seeds, which take
// pinned ends: the first mode's circle and its mirror image's, two points each), each point
// with its turn about the pin as a zero mode.
TEST(EquilibriaCli, PointsOfAContinuousFamilyAreListedAsOneFamily) {
  const auto dir = std::filesystem::temp_directory_path() / "kirchhoff_equilibria_families";
  std::filesystem::create_directories(dir);
  const std::string case_file = (dir / "pinned_twice.toml").string();
  std::ofstream(case_file) << kRodPinnedTwiceAtOnePoint;
  const std::string args = "equilibria " + case_file + " --max 4";
  const std::string text = (dir / "out.txt").string(), json = (dir / "out.json").string();
  ASSERT_EQ(run(args, text), 0);
  std::ifstream in_text(text);
  const std::string table((std::istreambuf_iterator<char>(in_text)), std::istreambuf_iterator<char>());
  EXPECT_NE(table.find("+1 zero"), std::string::npos) << table;
  // (Which of the four points share a family depends on the order the seeds reach them.)
  EXPECT_NE(table.find("(1 zero mode): 2 points of one continuous family"), std::string::npos) << table;
  ASSERT_EQ(run(args + " --json", json), 0);
  std::ifstream in_json(json);
  const nlohmann::json j = nlohmann::json::parse(in_json);
  const int families = j["families"].get<int>();
  EXPECT_GE(families, 2);
  EXPECT_NE(table.find("): 0 isolated, 4 with zero modes on " + std::to_string(families) + " continuous families (see below)"),
            std::string::npos)
      << table;
  ASSERT_EQ(j["equilibria"].size(), 4u);
  std::map<int, int> members;
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(j["equilibria"][k]["isolated"], false) << k;
    ASSERT_TRUE(j["equilibria"][k]["family"].is_number()) << k;
    ++members[j["equilibria"][k]["family"].get<int>()];
    EXPECT_EQ(j["equilibria"][k]["stability"]["zero_modes"], 1) << k;
  }
  // The families numbered 1 to their count, one of them with two of the points at least.
  ASSERT_EQ(members.size(), static_cast<size_t>(families));
  for (int f = 1; f <= families; ++f) EXPECT_EQ(members.count(f), 1u) << f;
  int largest = 0;
  for (const auto& [f, count] : members) largest = std::max(largest, count);
  EXPECT_GE(largest, 2);
}

}  // namespace
}  // namespace kirchhoff
