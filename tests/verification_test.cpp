// No result is called converged unless it is one: NaN and inf never pass Newton's test, a
// converged solve is checked again (verification.hpp), solves end within their wall-clock limit,
// and both steppers give the same equilibrium on every shipped case.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/shooting/newton.hpp"
#include "kirchhoff/shooting/verification.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// F(x) = x - 1 in every component, with component `poisoned` replaced by `value`.
class PoisonedSystem final : public NonlinearSystem {
 public:
  PoisonedSystem(int poisoned, double value) : poisoned_(poisoned), value_(value) {}
  int size() const override { return 3; }
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, std::string*) const override {
    *F = x.array() - 1.0;
    (*F)[poisoned_] = value_;
    if (J) *J = Eigen::MatrixXd::Identity(3, 3);
    return true;
  }

 private:
  int poisoned_;
  double value_;
};

TEST(MaxAbsOrNan, SeesEveryNonFiniteEntry) {
  EXPECT_EQ(max_abs_or_nan(Eigen::Vector3d(1.0, -3.0, 2.0)), 3.0);
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d v(1e-20, 1e-20, 1e-20);
    v[i] = NAN;
    EXPECT_TRUE(std::isnan(max_abs_or_nan(v))) << "NaN at " << i;
    v[i] = -INFINITY;
    EXPECT_TRUE(std::isnan(max_abs_or_nan(v))) << "inf at " << i;
  }
  EXPECT_EQ(max_abs_or_nan(Eigen::VectorXd()), 0.0);
}

// Eigen's lpNorm<Infinity> skipped a NaN in some positions, so a residual of NaN beside tiny
// entries passed `norm <= tolerance`: wherever the NaN sits, the solve is not converged.
TEST(NewtonOnNonFiniteResiduals, NeverConverges) {
  for (int i = 0; i < 3; ++i)
    for (double poison : {double(NAN), double(INFINITY)}) {
      const PoisonedSystem system(i, poison);
      Eigen::VectorXd x = Eigen::VectorXd::Ones(3);
      NewtonOptions options;
      options.fallback_search = true;  // the NLopt search must not turn it into a success either
      const NewtonSummary s = solve_with_fallback(system, x, options);
      EXPECT_FALSE(s.converged()) << i << " " << poison;
      EXPECT_EQ(s.status, SolverStatus::NotFinite) << i << " " << poison << ": " << s.brief_report();
    }
}

// Each evaluation takes 50 ms and F = 1 + 1 / (1 + x^2) has no root, so Newton and the NLopt
// search after it would go on for minutes: the 0.2 s limit stops both.
class SlowSystem final : public NonlinearSystem {
 public:
  int size() const override { return 1; }
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, std::string*) const override {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    *F = Eigen::VectorXd::Constant(1, 1.0 + 1.0 / (1.0 + x[0] * x[0]));
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, -2.0 * x[0] / std::pow(1.0 + x[0] * x[0], 2));
    return true;
  }
};

TEST(NewtonWallClockLimit, StopsWithTimeLimit) {
  const SlowSystem system;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.3);
  NewtonOptions options;
  options.max_iterations = 10000;
  options.max_backtracks = 0;
  options.max_seconds = 0.2;
  const auto start = std::chrono::steady_clock::now();
  const NewtonSummary s = solve_with_fallback(system, x, options);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_FALSE(s.converged());
  // Not a timing assert on speed: the limit plus a few 50 ms evaluations, with a wide margin
  // for a loaded machine. Without the limit this solve would run for minutes.
  EXPECT_LT(elapsed, 5.0) << s.brief_report();
  EXPECT_TRUE(s.status == SolverStatus::TimeLimit || s.status == SolverStatus::LineSearchFailed) << s.brief_report();
}

TEST(NewtonOptionsValidation, RefusesNonFiniteTimeLimit) {
  NewtonOptions o;
  o.max_seconds = INFINITY;
  EXPECT_FALSE(o.validate().empty());
  o.max_seconds = -1;
  EXPECT_FALSE(o.validate().empty());
  o.max_seconds = 10;
  EXPECT_TRUE(o.validate().empty());
}

// continue --samples 1e9 or --max-points 1e12 ran out of memory instead of being refused.
TEST(ContinuationOptionsValidation, BoundsSamplesAndPoints) {
  RodContinuationOptions o;
  o.parameter = "P";
  EXPECT_EQ(o.validate(), "");
  o.samples = 100001;
  EXPECT_NE(o.validate().find("samples"), std::string::npos);
  o.samples = 101;
  o.max_points = 10000001;
  EXPECT_NE(o.validate().find("max_points"), std::string::npos);
}

TEST(ProfileFailure, NamesNaNAndTheSoftWall) {
  RodModel model;
  std::vector<RodPoint> profile(3);
  for (int i = 0; i < 3; ++i) profile[i].s = 0.5 * i;
  EXPECT_EQ(profile_failure(model, profile), "");
  profile[1].n.x() = NAN;
  EXPECT_NE(profile_failure(model, profile).find("NaN"), std::string::npos);
  profile[1].n.x() = 0.0;
  model.field = std::make_shared<BarrierWall>(1e-3, 0.1, Vec3::UnitY());
  EXPECT_EQ(profile_failure(model, profile), "");
  profile[2].r.y() = 0.1 + 1e-6;  // beyond the wall at y = 0.1
  EXPECT_NE(profile_failure(model, profile).find("soft wall"), std::string::npos) << profile_failure(model, profile);
}

// An extensible cantilever (A3 = 10) under a compressive dead load P: straight, stretch v3 =
// 1 - P/A3. Below A3 it converges; at P = 12 the equations are solved with v3 = -0.2 (the tip at
// x = -0.2), a rod turned inside out, which is a check failure naming the stretch, not "converged".
TEST(ProfileFailure, AnExtensibleRodCompressedPastZeroLengthIsNoSolution) {
  const std::string text = R"(model = "planar"
[parameters]
P = 5.0
[rod]
length = 1.0
B = 1.0
extensible = true
A1 = 100.0
A3 = 10.0
[start]
type = "clamped"
position = [0, 0]
[end]
type = "loaded"
force = ["-P", 0]
[guess]
force = ["-P", 0]
)";
  for (const double P : {5.0, 12.0}) {
    const Case c = load_case_text(text, "squeezed.toml", {{"P", P}});
    CaseSolveOptions direct;
    direct.direct = true;
    const CaseSolve solved = solve_case(c, direct);
    if (P < 10.0) {
      EXPECT_TRUE(solved.converged()) << solved.message;
      continue;
    }
    EXPECT_EQ(solved.summary().status, SolverStatus::CheckFailed);
    EXPECT_THAT(solved.summary().message, ::testing::HasSubstr("compressed to zero or negative length"));
    EXPECT_THAT(solved.summary().message, ::testing::HasSubstr("v3 = -0.2"));
  }
}

// A solve of the soft wall at a range b = 1e-20 once "converged" with the rod beyond the wall:
// now it is never reported converged with a negative gap.
TEST(SoftWall, NoConvergedSolutionBeyondTheWall) {
  for (double log_b : {-20.0, -25.0}) {
    const Case c = load_case(testing::case_path("soft_wall.toml"), {{"log_b", log_b}});
    DefinitionSolve solved = solve_definition(c.definition, c.start_guess);
    const Solution sol = make_solution(*solved.problem, solved.result, 401, {"gap"});
    if (sol.result.summary.converged()) {
      EXPECT_GT(sol.derived.at("gap"), 0.0) << log_b;
      for (const RodPoint& p : sol.profile) EXPECT_LT(p.r.y(), 0.1) << "log_b " << log_b << " s " << p.s;
    }
  }
}

// The residual tolerance is absolute: a rod of length 1e-100 meets it at the case's guess, whose
// P = 12 is not the equilibrium (P = 4 K(k)^2 EI / L^2 ~ 1e201). Such a solve once converged after
// 0 iterations; now one Newton correction from the guess says its residual is small only by
// scale. At L = 1 a guess that is the solution itself (its correction ~1e-10, far below the
// 1e-4 allowed) still converges after 0 iterations.
TEST(ZeroIterationCheck, RefusesAResidualSmallOnlyByTheCasesScale) {
  const Case tiny = load_case(testing::case_path("simply_supported.toml"), {{"L", 1e-100}});
  const DefinitionSolve at_tiny_scale = solve_definition(tiny.definition, tiny.start_guess);
  EXPECT_EQ(at_tiny_scale.result.summary.status, SolverStatus::CheckFailed);
  EXPECT_NE(at_tiny_scale.result.summary.message.find("not meaningful at this case's scale"), std::string::npos)
      << at_tiny_scale.result.summary.message;

  const Case unit = load_case(testing::case_path("simply_supported.toml"));
  const DefinitionSolve first = solve_definition(unit.definition, unit.start_guess);
  ASSERT_TRUE(first.result.summary.converged());
  const ShootingResult again = solve(*first.problem, first.result.x);
  EXPECT_TRUE(again.summary.converged()) << again.summary.message;
  EXPECT_EQ(again.summary.iterations, 0);
}

// A closed isotropic twisted ring (clamped at both ends at one point, the end frame turned by 2 pi
// Tw about the tangent): turning the ring about its centreline leaves it an equilibrium, so the
// equilibria form a continuous family and the Jacobian is singular there. The guess is the
// circular ring itself (residual 6e-10) and one Newton correction moves it by 2.6e-4: that is the
// singular matrix, not the case's scale, and the message says so (it said "give lengths ... in
// units that make them of order 1" for this case of order 1).
TEST(ZeroIterationCheck, NamesANearlySingularJacobianAsNotIsolatedEquilibria) {
  const Case ring = load_case_text(R"(
model = "spatial"
[parameters]
Tw = 1.0
[rod]
length = "2*_pi"
B1 = 1.0
B2 = 1.0
B3 = 0.8
[start]
type = "clamped"
position = [0, 0, 0]
[end]
type = "clamped"
position = [0, 0, 0]
orientation = { axis = [0, 0, 1], angle = "2*_pi*Tw" }
track_turns = true
[guess]
force = [0, 0.8, 0]
moment = [0, 1.0, 0.8]
[solver]
tolerance = 1e-8
)",
                                   "ring.toml");
  const ShootingProblem problem(ring.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(ring.start_guess));
  EXPECT_EQ(r.summary.status, SolverStatus::CheckFailed);
  EXPECT_NE(r.summary.message.find("the Jacobian is nearly singular there"), std::string::npos) << r.summary.message;
  EXPECT_EQ(r.summary.message.find("units that make them of order 1"), std::string::npos) << r.summary.message;
}

// Both steppers give the same equilibrium on every shipped case. Dopri5 returned NaN profiles
// (odeint's dense output sampled s = 0 before its first step) that the solve called converged.
class BothSteppers : public ::testing::TestWithParam<std::string> {};

TEST_P(BothSteppers, GiveTheSameEquilibrium) {
  const std::string name = GetParam();
  Solution by[2];
  for (int k = 0; k < 2; ++k) {
    Case c = load_case(testing::case_path(name));
    c.definition.options.integrator.stepper =
        k == 0 ? IntegratorOptions::Stepper::RungeKutta78 : IntegratorOptions::Stepper::Dopri5;
    c.definition.options.integrator.sensitivity_tol = 0.0;
    c.definition.options.integrator.closed_form = false;  // (the steppers themselves, on every case)
    DefinitionSolve solved = solve_definition(c.definition, c.start_guess);
    by[k] = make_solution(*solved.problem, solved.result, 101, c.derived);
    ASSERT_TRUE(by[k].result.summary.converged()) << name << (k ? " dopri5: " : " rk78: ")
                                                  << by[k].result.summary.brief_report();
    for (const RodPoint& p : by[k].profile) ASSERT_TRUE(p.r.allFinite() && p.n.allFinite() && p.m.allFinite());
  }
  // Both solve to the case's residual tolerance (<= 1e-8) with local errors <= the case's 1e-12
  // per step; the global error of either is ~1e-10 of the scale, and the derived quantities
  // amplify it by their conditioning (<= ~1e2 on these cases): 1e-6 of the scale bounds it.
  for (const auto& [quantity, value] : by[0].derived) {
    const double other = by[1].derived.at(quantity);
    if (std::isnan(value)) {
      EXPECT_TRUE(std::isnan(other)) << name << " " << quantity;
      continue;
    }
    EXPECT_NEAR(other, value, 1e-6 * std::max(1.0, std::abs(value))) << name << " " << quantity;
  }
  EXPECT_NEAR(by[1].invariants.H.mean, by[0].invariants.H.mean, 1e-6 * std::max(1.0, std::abs(by[0].invariants.H.mean)))
      << name;
}

std::vector<std::string> shipped_cases() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(KIRCHHOFF_CASES_DIR))
    if (entry.path().extension() == ".toml") names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  return info.param.substr(0, info.param.size() - 5);  // without ".toml"
}

INSTANTIATE_TEST_SUITE_P(ShippedCases, BothSteppers, ::testing::ValuesIn(shipped_cases()), test_name);

}  // namespace
}  // namespace kirchhoff
