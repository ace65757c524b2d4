// The sliding sleeve (Figs. 6-7, eq. 55) and the Elastica arm scale (Fig. 8). The solver closes
// each problem with the continuity of H across the sleeve exit; the tests check the result
// against the stationarity of the total energy in the sliding length, which does not use H.
#include <cmath>
#include <cstdio>

#include "test_support.hpp"

namespace kirchhoff {
namespace {

// Energy of the loads and the rod for a fixed length outside the sleeve: the same case with the
// length given and the exit's H condition dropped.
struct FixedLength {
  ProblemDefinition definition;
  Eigen::VectorXd start;  // the sliding solution's state at s = 0: stays on its branch
  ShootingResult solve_at(double ell) const {
    ProblemDefinition d = definition;
    d.parameters.set("ell", ell);
    const ShootingProblem problem(d);
    return solve(problem, start);
  }
};

TEST(Sleeve, Eq55AndTheContinuityOfHAcrossTheExit) {
  const auto solved = testing::solve_case("sleeve.toml");
  const auto& d = solved.solution.derived;
  const double P = 10.0, P_prime = 30.0;
  // Eq. (55): P' = P + EI kappa_B^2 / 2, and H_out(B) = H_in = -P.
  EXPECT_NEAR(P_prime, P + 0.5 * d.at("kappa_end") * d.at("kappa_end"), 1e-9 * P_prime);
  EXPECT_NEAR(d.at("H_end"), -P, 1e-9 * P);
  EXPECT_LE(solved.solution.invariants.H.relative_spread(), 1e-9);
}

TEST(Sleeve, LengthOutsideMakesTheTotalEnergyStationary) {
  Case c = load_case(testing::case_path("sleeve.toml"));
  const double P = c.definition.parameters["P"], P_prime = c.definition.parameters["P_prime"];
  const ShootingProblem problem(c.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(r.summary.converged());
  const double ell = r.parameters["ell"];
  FixedLength fixed;
  fixed.definition = c.definition;
  fixed.definition.unknown_parameters.clear();
  fixed.definition.end = EndCondition::clamped(constant(Vec3::Zero()), constant_orientation({}));
  fixed.definition.options.newton.residual_tolerance = 3e-12;  // just above the residual's floor
  fixed.start = r.x.head(problem.state_size());
  // Pi(ell) = U(ell) - P' x_A(ell) + P (L_total - ell): dPi/dell = dU/dell - P' dx_A/dell - P.
  auto energy_terms = [&](double l, double* U, double* xA) {
    const ShootingResult s = fixed.solve_at(l);
    ASSERT_TRUE(s.summary.converged()) << s.summary.brief_report();
    ProblemDefinition d = fixed.definition;
    d.parameters.set("ell", l);
    const ShootingProblem at(d);
    const Solution sol = make_solution(at, s, 11, {"elastic_energy"});
    *U = sol.derived.at("elastic_energy");
    *xA = sol.profile.front().r.x();
  };
  // Central differences, Richardson-extrapolated. The truncation left is ~C h^4 with a large C (U
  // varies fast: the rod is only 6% longer than critical): measured 1e-5 of P at h = 1e-3 and
  // 1.5e-8 at h = 2e-4, so h = 5e-5 brings it to ~6e-11; the round-off of energies computed to
  // ~1e-14 relative is ~1e-13 / h ~ 2e-9 absolute, 2e-10 of P.
  auto derivative = [&](double h, double* dU, double* dx) {
    double Up, xp, Um, xm;
    energy_terms(ell + h, &Up, &xp);
    energy_terms(ell - h, &Um, &xm);
    *dU = (Up - Um) / (2 * h);
    *dx = (xp - xm) / (2 * h);
  };
  double dU1, dx1, dU2, dx2;
  derivative(1e-4, &dU1, &dx1);
  derivative(5e-5, &dU2, &dx2);
  const double dU = (4 * dU2 - dU1) / 3, dx = (4 * dx2 - dx1) / 3;
  // Stationary: the push P the sleeve can balance is dU/dell - P' dx_A/dell, equal to the given P.
  EXPECT_NEAR((dU - P_prime * dx) / P, 1.0, 1e-9);
}

TEST(ArmScale, TangentAtTheLoadedEndIsHorizontal) {
  const auto solved = testing::solve_case("arm_scale.toml");
  const auto& d = solved.solution.derived;
  // Fig. 8: H_A = 0 (unloaded end inside the sleeve) = H_C = -W sin(theta_C) (kappa_C = 0).
  EXPECT_NEAR(d.at("theta_end"), 0.0, 1e-9);
  EXPECT_NEAR(d.at("H_start"), 0.0, 1e-9);
  EXPECT_NEAR(d.at("H_end"), 0.0, 1e-9);
  EXPECT_NEAR(d.at("kappa_end"), 0.0, 1e-9);
}

TEST(ArmScale, LengthOutsideMakesTheTotalEnergyStationary) {
  Case c = load_case(testing::case_path("arm_scale.toml"));
  const double W = c.definition.parameters["W"];
  const ShootingProblem problem(c.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(r.summary.converged());
  const double ell = r.parameters["ell"];
  FixedLength fixed;
  fixed.definition = c.definition;
  fixed.definition.unknown_parameters.clear();
  fixed.definition.start = EndCondition::clamped(constant(Vec3::Zero()), [&](const Parameters& p) {
    return OrientationTarget{Vec3::UnitZ(), p["alpha"]};
  });
  fixed.definition.options.newton.residual_tolerance = 3e-12;  // just above the residual's floor
  fixed.start = r.x.head(problem.state_size());
  // Pi(ell) = U(ell) + W y_C(ell) (the part inside the sleeve is straight and unloaded).
  auto Pi = [&](double l) {
    const ShootingResult s = fixed.solve_at(l);
    EXPECT_TRUE(s.summary.converged()) << s.summary.brief_report();
    ProblemDefinition d = fixed.definition;
    d.parameters.set("ell", l);
    const ShootingProblem at(d);
    const Solution sol = make_solution(at, s, 11, {"elastic_energy", "tip_y"});
    return sol.derived.at("elastic_energy") + W * sol.derived.at("tip_y");
  };
  auto central = [&](double h) { return (Pi(ell + h) - Pi(ell - h)) / (2 * h); };
  const double dPi = (4 * central(1e-3) - central(2e-3)) / 3;
  EXPECT_NEAR(dPi / W, 0.0, 1e-9);
}

}  // namespace
}  // namespace kirchhoff
