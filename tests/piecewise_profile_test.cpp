// Material properties given piecewise along the rod: their jumps are located
// (model/detail/profile_jumps.hpp) and the integrations land on them, so a short stretch of a
// different stiffness is never stepped across unseen.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "kirchhoff/analysis/vibration.hpp"
#include "kirchhoff/model/detail/profile_jumps.hpp"
#include "kirchhoff/shooting/shooting.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

TEST(ProfileJumps, MayJumpWhereTheTextComparesOrSteps) {
  EXPECT_TRUE(may_jump("EI*(1 - 0.9*(s > 0.4 && s < 0.5))"));
  EXPECT_TRUE(may_jump("s < a ? B1 : B2"));
  EXPECT_TRUE(may_jump("1 + sign(s - 0.5)"));
  EXPECT_TRUE(may_jump("2 + rint(4*s)"));
  EXPECT_FALSE(may_jump("EI*(1 + taper*(s/L - 0.5))"));
  EXPECT_FALSE(may_jump("1 + exp(-s^2) * cos(sinh(s))"));  // (names containing "sign" or "rint": none)
}

TEST(ProfileJumps, AShortStretchIsLocatedBetweenAdjacentDoubles) {
  // 1e-3 of the rod long, six samples' spacing: both ends, each to one ulp.
  const auto f = [](double s) { return 1.0 - 0.99 * (s > 0.4013 && s < 0.4023); };
  const std::vector<ProfileJump> jumps = locate_jumps(f, 1.0);
  ASSERT_EQ(jumps.size(), 2u);
  EXPECT_EQ(jumps[0].after, std::nextafter(jumps[0].before, 1.0));
  EXPECT_EQ(f(jumps[0].before), 1.0);
  EXPECT_NEAR(f(jumps[0].after), 0.01, 1e-15);
  EXPECT_NEAR(jumps[0].before, 0.4013, 1e-15);
  EXPECT_NEAR(jumps[1].before, 0.4023, 1e-15);
  EXPECT_EQ(f(jumps[1].after), 1.0);
  // On a rod of length 3 the same stretch (scaled) is found where it is.
  const std::vector<ProfileJump> scaled = locate_jumps([&](double s) { return f(s / 3.0); }, 3.0);
  ASSERT_EQ(scaled.size(), 2u);
  EXPECT_NEAR(scaled[1].before, 3.0 * 0.4023, 1e-14);
}

TEST(ProfileJumps, ASteepSmoothProfileDoesNotJumpAndASlopedOneDoes) {
  // tanh over 1e-3 of the rod changes by ~1e3 ulp-widths' worth of nothing: no jump.
  EXPECT_TRUE(locate_jumps([](double s) { return 2.0 + std::tanh((s - 0.5) / 1e-3); }, 1.0).empty());
  // A jump of 0.3 on a slope that changes 1e-4 per sample: found, with its size.
  const auto sloped = [](double s) { return 1.0 + 2.0 * s + 0.3 * (s > 0.7); };
  const std::vector<ProfileJump> jumps = locate_jumps(sloped, 1.0);
  ASSERT_EQ(jumps.size(), 1u);
  EXPECT_NEAR(jumps[0].before, 0.7, 1e-15);
  EXPECT_NEAR(sloped(jumps[0].after) - sloped(jumps[0].before), 0.3, 1e-14);
  // And every check point: the samples and both sides of each jump.
  EXPECT_EQ(check_points(1.0, jumps).size(), static_cast<size_t>(kJumpSamples + 1 + 2));
}

// The straight column's buckling loads with bending stiffness EI_i on consecutive stretches of
// length h_i: (EI theta')' + P theta = 0 with theta' = 0 at both pinned ends. The transfer
// matrix of a uniform stretch, k = sqrt(P / EI), carries (theta, m = EI theta'); a load is
// critical where m(L) = 0 from (1, 0).
double end_moment(double P, const std::vector<std::pair<double, double>>& stretches) {
  double theta = 1.0, m = 0.0;
  for (const auto& [EI, h] : stretches) {
    const double k = std::sqrt(P / EI), c = std::cos(k * h), s = std::sin(k * h);
    const double next_theta = c * theta + s / (EI * k) * m;
    m = -EI * k * s * theta + c * m;
    theta = next_theta;
  }
  return m;
}

std::vector<double> critical_loads(const std::vector<std::pair<double, double>>& stretches, double up_to) {
  std::vector<double> loads;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    double a = up_to * (i + 0.5) / n, b = up_to * (i + 1.5) / n;
    if (end_moment(a, stretches) * end_moment(b, stretches) > 0) continue;
    for (int k = 0; k < 200 && b - a > 1e-14 * b; ++k) {
      const double c = 0.5 * (a + b);
      (end_moment(a, stretches) * end_moment(c, stretches) <= 0 ? b : a) = c;
    }
    loads.push_back(0.5 * (a + b));
  }
  return loads;
}

// euler_column.toml with its stiffness `B` (an expression of s), straight from P = 1, in
// `segments` shooting segments.
Case stepped_column(const std::string& B, int segments = 1) {
  std::string text = testing::case_text("euler_column.toml");
  const std::string uniform = "B = \"EI\"";
  EXPECT_NE(text.find(uniform), std::string::npos);
  text.replace(text.find(uniform), uniform.size(), "B = \"" + B + "\"");
  Case c = load_case_text(text, "stepped.toml", {{"P", 1.0}, {"theta_guess", 0.0}});
  c.definition.options.segments = segments;
  return c;
}

// The straight column continued in P to 40, its index at every point.
ContinuationResult continued_to_40(const Case& c) {
  const ShootingProblem problem(c.definition);
  RodContinuationOptions o;
  o.parameter = "P";
  o.target = 40.0;
  o.initial_step = 0.5;
  o.max_step = 5.0;
  o.samples = 21;
  o.compute_stability = true;
  RodContinuation run(problem, o);
  return run.run(problem.initial_unknowns(c.start_guess));
}

std::vector<double> branch_points_of(const ContinuationResult& r) {
  std::vector<double> out;
  for (const auto& p : r.points)
    if (p.type == PointType::BranchPoint) out.push_back(p.parameter);
  return out;
}

// The Euler column with a stretch of a hundredth of its stiffness 1e-3 long (a probe's case):
// before the jumps were located the integrator stepped across it and every branch point was the
// uniform column's (9.8696 = pi^2, where this column buckles at 8.2975), converged.
TEST(PiecewiseRod, ColumnWithAShortSoftStretchBucklesAtItsTransferMatrixLoads) {
  const ContinuationResult r = continued_to_40(stepped_column("EI*(1 - 0.99*(s > 0.4013 && s < 0.4023))"));
  const std::vector<double> branch_points = branch_points_of(r);
  const std::vector<double> exact = critical_loads({{1.0, 0.4013}, {0.01, 0.001}, {1.0, 1.0 - 0.4023}}, 40.0);
  ASSERT_EQ(exact.size(), 2u);  // 8.2975 and 37.159
  ASSERT_EQ(branch_points.size(), exact.size());
  // The branch points are located to the continuation's 1e-8 (continuation_test's kLocated).
  for (size_t k = 0; k < exact.size(); ++k) EXPECT_NEAR(branch_points[k] / exact[k], 1.0, 1e-8);
  // The straight column is stable below the first load and has index 1 past it.
  for (const auto& p : r.points) {
    if (!p.stability_index || p.type == PointType::BranchPoint) continue;
    EXPECT_EQ(*p.stability_index, p.parameter < exact[0] ? 0 : (p.parameter < exact[1] ? 1 : 2))
        << "P = " << p.parameter;
  }
}

// A jump on a profile sample (s = 0.3 among 201 samples, on "s > 0.3"): the stretch from it took
// its first stage's stiffness from the wrong side, which RKF78's error estimate cannot see, and
// the profile broke the end conditions the solve had met (a probe's: m(L) = 7.7e-4 at the pinned
// end of tapered.toml, tip off by 3.5e-5 on a 3D rod). The profile must meet them to the
// solve's residual.
TEST(PiecewiseRod, AJumpOnAProfileSampleKeepsTheEndConditions) {
  std::string planar = testing::case_text("tapered.toml");
  const std::string tapered = "B = \"EI0*(1 + taper*s/L)\"";
  ASSERT_NE(planar.find(tapered), std::string::npos);
  planar.replace(planar.find(tapered), tapered.size(), "B = \"EI0*(1 + 0.5*(s > 0.3 && s < 0.35))\"");
  const CaseSolve pinned = kirchhoff::solve_case(load_case_text(planar, "stepped.toml"));
  ASSERT_TRUE(pinned.converged()) << pinned.message;
  const RodPoint& end = pinned.solution->profile.back();
  EXPECT_NEAR(end.m.z(), 0.0, 1e-9);  // pinned: no moment
  EXPECT_NEAR(end.r.y(), 0.0, 1e-9);  // on the axis it slides along

  // The Reissner case made inextensible, its B1 stepped up on [0.3, 0.35]: the end's moment is the
  // one applied, (0, 0.2, 0.3).
  std::string spatial = testing::case_text("reissner.toml");
  for (const std::string line : {"extensible = true\n", "A1 = 30.0\n", "A2 = 40.0\n", "A3 = 50.0\n"}) {
    ASSERT_NE(spatial.find(line), std::string::npos) << line;
    spatial.erase(spatial.find(line), line.size());
  }
  spatial.replace(spatial.find("B1 = 1.0"), 8, "B1 = \"1 + 0.5*(s > 0.3 && s < 0.35)\"");
  const CaseSolve loaded = kirchhoff::solve_case(load_case_text(spatial, "stepped_3d.toml"));
  ASSERT_TRUE(loaded.converged()) << loaded.message;
  const RodPoint& tip = loaded.solution->profile.back();
  EXPECT_NEAR(tip.m.x(), 0.0, 1e-9);
  EXPECT_NEAR(tip.m.y(), 0.2, 1e-9);
  EXPECT_NEAR(tip.m.z(), 0.3, 1e-9);
}

// The column stepped to a fifth of its stiffness at mid-span, shot in two segments whose node is
// the jump (a probe's: 2.985331 and 16.199424 against 2.9946520 and 16.2233911 exactly; one
// segment was exact). The segments start and end on the jump's sides now.
TEST(PiecewiseRod, AJumpOnASegmentNodeKeepsTheCriticalLoads) {
  const std::vector<double> branch_points = branch_points_of(continued_to_40(stepped_column("EI*(s < 0.5 ? 1 : 0.2)", 2)));
  const std::vector<double> exact = critical_loads({{1.0, 0.5}, {0.2, 0.5}}, 40.0);
  ASSERT_EQ(exact.size(), 3u);  // 2.9947, 16.223, 35.349
  ASSERT_EQ(branch_points.size(), exact.size());
  for (size_t k = 0; k < exact.size(); ++k) EXPECT_NEAR(branch_points[k] / exact[k], 1.0, 1e-8);
}

// The pinned-pinned beam under a compression P with EI_i on consecutive stretches:
// EI w'''' + P w'' = rho omega^2 w, carried as (w, w', M = EI w'', V = M' + P w'), all continuous
// across a jump, by classical RK4 on fine fixed steps (independent of the library's integrator).
// Returns det [w(L), M(L)] of the two fields with w = M = 0 at s = 0.
double pinned_beam_determinant(double omega2, double P, const std::vector<std::pair<double, double>>& stretches) {
  using State = std::array<double, 4>;
  std::array<State, 2> y{State{0.0, 1.0, 0.0, 0.0}, State{0.0, 0.0, 0.0, 1.0}};
  for (const auto& [EI, h] : stretches) {
    const double stiffness = EI;
    const auto rhs = [&](const State& q) {
      return State{q[1], q[2] / stiffness, q[3] - P * q[1], omega2 * q[0]};
    };
    const int steps = static_cast<int>(std::ceil(h * 4000));
    const double dt = h / steps;
    for (State& q : y)
      for (int k = 0; k < steps; ++k) {
        const State k1 = rhs(q);
        State a, b, c;
        for (int i = 0; i < 4; ++i) a[i] = q[i] + 0.5 * dt * k1[i];
        const State k2 = rhs(a);
        for (int i = 0; i < 4; ++i) b[i] = q[i] + 0.5 * dt * k2[i];
        const State k3 = rhs(b);
        for (int i = 0; i < 4; ++i) c[i] = q[i] + dt * k3[i];
        const State k4 = rhs(c);
        for (int i = 0; i < 4; ++i) q[i] += dt / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
      }
  }
  return y[0][0] * y[1][2] - y[1][0] * y[0][2];
}

// vibrate matches the fields shot from both ends at mid-span: with the jump there its shots
// started on the wrong side (a probe's: omega^2 = 506.068 and -21.748 against 507.539 and
// -21.640).
TEST(PiecewiseRod, VibrationsWithAJumpAtMidSpanMatchATransferComputation) {
  const CaseSolve straight = kirchhoff::solve_case(reload_case(stepped_column("EI*(s < 0.5 ? 1 : 0.2)"), {{"P", 5.0}, {"theta_guess", 0.0}}));
  ASSERT_TRUE(straight.converged()) << straight.message;
  VibrationOptions options;
  options.modes = 2;
  const VibrationProblem vib(*straight.solved.problem, straight.solved.result.x, options);
  const std::vector<std::pair<double, double>> beam{{1.0, 0.5}, {0.2, 0.5}};
  std::vector<double> omega2;
  for (double w : vib.frequencies()) omega2.push_back(w * w);
  for (double w2 : vib.negative_omega2()) omega2.push_back(w2);
  ASSERT_EQ(omega2.size(), 3u);
  for (double w2 : omega2) {
    // A root of the independent determinant: it changes sign within 1e-6 relative of omega^2
    // (RK4 at 4000 steps per unit length: ~1e-10).
    const double d = 1e-6 * std::abs(w2);
    EXPECT_LT(pinned_beam_determinant(w2 - d, 5.0, beam) * pinned_beam_determinant(w2 + d, 5.0, beam), 0.0)
        << "omega^2 = " << w2;
  }
}

// The energy across a jump: a cantilever under an end couple M bends with curvature M / B(s), and
// its total potential energy is integral M^2 / (2 B) - M theta(L) = -M^2 I / 2, I = integral ds / B,
// in closed form (B = 1 on [0, 0.3], 0.2 after: I = 3.8). Simpson across the jump erred by its
// spacing times the jump (a probe's stepped column: 1e-4 relative).
TEST(PiecewiseRod, TheEnergyOfACantileverUnderACoupleIsItsClosedForm) {
  const std::string text = R"(model = "planar"
[parameters]
M = 1.0
[rod]
length = 1.0
B = "s < 0.3 ? 1 : 0.2"
[start]
type = "clamped"
position = [0, 0]
[end]
type = "loaded"
force = [0, 0]
moment = [0, 0, "M"]
[guess]
force = [0, 0]
moment = [0, 0, "-M"]
)";
  const Case c = load_case_text(text, "couple.toml");
  const CaseSolve solved = kirchhoff::solve_case(c);
  ASSERT_TRUE(solved.converged()) << solved.message;
  const double I = 0.3 + 0.7 / 0.2;
  EXPECT_NEAR(total_potential_energy(*solved.solved.problem, solved.solved.result.x), -0.5 * I, 1e-10);
}

}  // namespace
}  // namespace kirchhoff
