// The shooting Jacobian from the variational equations against central finite differences.
#include "kirchhoff/shooting/newton.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// Central differences with h = 1e-6 (1 + |x|) have truncation error ~h^2 |F'''| ~ 1e-11 and
// round-off ~ eps |F| / h ~ 1e-9 (the residual is an integrated quantity accurate to ~1e-12,
// so the round-off term is really ~1e-12/1e-6 = 1e-6 of |F|'s scale at worst). We compare with
// a 1e-6 tolerance relative to the largest entry, as the issue asks.
constexpr double kJacobianTolerance = 1e-6;

void expect_jacobians_agree(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  Eigen::VectorXd F;
  Eigen::MatrixXd J, J_fd;
  std::string failure;
  ASSERT_TRUE(problem.evaluate(x, &F, &J, &failure)) << failure;
  ASSERT_TRUE(finite_difference_jacobian(problem, x, 1e-6, &J_fd));
  const double scale = std::max(1.0, J.cwiseAbs().maxCoeff());
  EXPECT_LE((J - J_fd).cwiseAbs().maxCoeff(), kJacobianTolerance * scale)
      << "variational:\n" << J << "\nfinite differences:\n" << J_fd;
}

// A point near, but not at, the solution so that no term vanishes by accident.
Eigen::VectorXd perturbed_guess(const ShootingProblem& problem, const Case& c, double amount) {
  Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
  for (int i = 0; i < x.size(); ++i) x[i] += amount * std::sin(1.0 + 3.7 * i);
  return x;
}

struct JacobianCase {
  const char* file;
  ParameterOverrides overrides;
  const char* phase;
  int segments;
};

class VariationalJacobian : public ::testing::TestWithParam<JacobianCase> {};

TEST_P(VariationalJacobian, EqualsFiniteDifferences) {
  const auto& param = GetParam();
  Case c = load_case(testing::case_path(param.file), param.overrides, param.phase);
  c.definition.options.segments = param.segments;
  const ShootingProblem problem(c.definition);
  expect_jacobians_agree(problem, perturbed_guess(problem, c, 0.05));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, VariationalJacobian,
    ::testing::Values(JacobianCase{"simply_supported.toml", {{"theta0", 1.5}}, "", 1},
                      JacobianCase{"simply_supported.toml", {{"theta0", 1.5}}, "", 3},
                      JacobianCase{"tapered.toml", {}, "", 1},
                      JacobianCase{"heavy_cantilever.toml", {}, "", 2},
                      JacobianCase{"twisted_clamped.toml", {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}}, "axial", 1},
                      JacobianCase{"twisted_clamped.toml",
                                   {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}}, "axial", 3},
                      JacobianCase{"twisted_clamped.toml", {{"phi", 8.0}, {"m_lateral", 0.5}}, "", 2},
                      JacobianCase{"reissner.toml", {}, "", 1},
                      JacobianCase{"reissner.toml", {}, "", 4}),
    [](const ::testing::TestParamInfo<JacobianCase>& info) {
      std::string name = info.param.file;
      name = name.substr(0, name.find('.')) + "_" + std::to_string(info.param.segments) + "seg" +
             (std::string(info.param.phase).empty() ? "" : "_phase") + "_" + std::to_string(info.index);
      return name;
    });

// With the axial phase condition the unfolding couple's column comes from the flows' own
// sensitivity (SegmentFlow::dy_dunfolding), not from two more integrations: F + J costs one pass
// with the variational equations, 1.2 residuals' right-hand sides here (3.2 with the central
// differences); the bound is 2. (The column's values: EqualsFiniteDifferences above.)
TEST(VariationalJacobian, UnfoldingColumnNeedsNoFurtherIntegration) {
  Case c = load_case(testing::case_path("twisted_clamped.toml"),
                     {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}}, "axial");
  const ShootingProblem problem(c.definition);
  const Eigen::VectorXd x = perturbed_guess(problem, c, 0.05);
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  long before = problem.rhs_evaluations();
  ASSERT_TRUE(problem.evaluate(x, &F, nullptr, &failure)) << failure;
  const long residual_rhs = problem.rhs_evaluations() - before;
  before = problem.rhs_evaluations();
  ASSERT_TRUE(problem.evaluate(x, &F, &J, &failure)) << failure;
  EXPECT_LT(problem.rhs_evaluations() - before, 2 * residual_rhs);
}

// The planar variational equations written out (planar_equations.cpp) for an extensible,
// shearable rod without a field, with stiffnesses and natural strains that vary along it: every
// term of their linearisation (the internal force's components in the frame, the s-dependence).
TEST(VariationalJacobian, ExtensiblePlanarRodWithoutField) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 1.5}});
  c.definition.model = [inner = c.definition.model](const Parameters& p) {
    RodModel m = inner(p);
    m.extensible = true;
    m.A[0] = Profile([](double s) { return 30.0 + 10.0 * s; });
    m.A[2] = Profile([](double s) { return 50.0 - 20.0 * s; });
    m.v_hat[0] = Profile(0.02);
    m.u_hat[1] = Profile([](double s) { return 0.3 * s; });
    m.B[1] = Profile([](double s) { return 1.0 + 0.5 * s; });
    return m;
  };
  const ShootingProblem problem(c.definition);
  expect_jacobians_agree(problem, perturbed_guess(problem, c, 0.05));
}

TEST(FiniteDifferenceFallback, ConvergesToTheSameSolution) {
  Case c = load_case(testing::case_path("simply_supported.toml"), {{"theta0", 2.0}});
  const ShootingProblem exact(c.definition);
  ShootingResult a = solve(exact, exact.initial_unknowns(c.start_guess));
  c.definition.options.newton.finite_difference_jacobian = true;
  const ShootingProblem fd(c.definition);
  ShootingResult b = solve(fd, fd.initial_unknowns(c.start_guess));
  ASSERT_TRUE(a.summary.converged());
  ASSERT_TRUE(b.summary.converged());
  // Both converge to |F| <= 1e-10 on the same residual function.
  EXPECT_NEAR(a.parameters["P"], b.parameters["P"], 1e-9 * a.parameters["P"]);
}

// The residual of `c` at sensitivity_tol 1e-8 is bit for bit the one without sensitivities, and
// its Jacobian within `bound` (relative to the largest entry) of the one at sensitivity_tol 0, at
// the case's guess perturbed by `amount`; the difference is above 0 (the looser pass did run).
void expect_loose_jacobian_within(Case c, double amount, double bound) {
  c.definition.options.integrator.closed_form = false;  // (the planar rods' closed form has no looser pass)
  c.definition.options.integrator.sensitivity_tol = 0.0;
  const ShootingProblem tight(c.definition);
  c.definition.options.integrator.sensitivity_tol = 1e-8;
  const ShootingProblem loose(c.definition);
  const Eigen::VectorXd x = perturbed_guess(tight, c, amount);
  Eigen::VectorXd F_tight, F_loose, F_alone;
  Eigen::MatrixXd J_tight, J_loose;
  std::string failure;
  ASSERT_TRUE(tight.evaluate(x, &F_tight, &J_tight, &failure)) << failure;
  ASSERT_TRUE(loose.evaluate(x, &F_loose, &J_loose, &failure)) << failure;
  ASSERT_TRUE(loose.evaluate(x, &F_alone, nullptr, &failure)) << failure;
  EXPECT_EQ((F_loose - F_alone).cwiseAbs().maxCoeff(), 0.0);
  const double scale = J_tight.cwiseAbs().maxCoeff();
  const double difference = (J_loose - J_tight).cwiseAbs().maxCoeff() / scale;
  EXPECT_LE(difference, bound) << "tight:\n" << J_tight << "\nloose:\n" << J_loose;
  EXPECT_GT(difference, 0.0);  // the looser integration did run
}

// sensitivity_tol integrates the variational equations at a looser tolerance than the state.
// The residual must be the very number an evaluation without sensitivities gives (the
// corrector's chords compare the two), and Phi must still be the Jacobian to about the looser
// tolerance: RK78's error per step is held to 1e-8 of each component, and a segment of ~10 R
// takes tens of steps, so ~1e-7 of the largest entry is the expected error, 1e-5 the bound
// (measured here, at 1.5 turns where the barrier barely acts: 5e-13).
TEST(LooseSensitivities, KeepTheResidualAndTheJacobianToTheirTolerance) {
  expect_loose_jacobian_within(load_case(testing::case_path("plectoneme.toml"), {{"turns", 1.5}}), 0.01, 1e-5);
}

// The planar rod's looser matrices come from its variational equations written out (sin and cos
// shared with the state) rather than from dual numbers: the same bounds as above, on an
// inextensible rod and on an extensible, shearable one with natural curvature and a stiffness
// varying along s (every term of the written-out equations). The exact matrices (sensitivity_tol
// 0) keep the dual numbers, so the difference is the looser tolerance's: ~1e-8 per step over a
// few tens of steps, 1e-5 the bound as above; a wrong term would show at O(1).
TEST(LooseSensitivities, PlanarWrittenOutVariationsMatchTheDualNumbers) {
  const Case extensible = load_case_text(R"(model = "planar"
[rod]
length = 1.0
B = "1 + 0.5*s"
extensible = true
A1 = 20.0
A3 = 35.0
u_hat = [0, 0.8, 0]
v_hat = [0.05, 0, 1.02]
[start]
type = "clamped"
position = [0, 0]
[end]
type = "loaded"
force = [-1.5, 2.0]
moment = [0, 0, 0.4]
[guess]
force = [-1.5, 2.0]
)",
                                         "planar_extensible.toml");
  for (const Case& c : {load_case(testing::case_path("euler_column.toml")), extensible}) {
    SCOPED_TRACE(c.path);
    expect_loose_jacobian_within(c, 0.05, 1e-5);
  }
}

// The spatial rod without field or cylinder takes all its matrices from its variational
// equations written out (spatial_variations.hpp), the exact ones too: both are checked against
// central differences (kJacobianTolerance, as above), and the looser ones against the exact ones
// (1e-5, as above), on the twisted rod buckled with the axial phase condition (its unknown
// unfolding couple perturbed off zero, so the mu dR e3 terms and the couple's own column act) and
// on an extensible, shearable rod with natural curvature and twist and stiffnesses varying along
// s. A wrong term would show at O(1). (flow_directions_test compares them with the dual numbers.)
TEST(LooseSensitivities, SpatialWrittenOutVariationsMatchFiniteDifferences) {
  const Case extensible = load_case_text(R"(model = "spatial"
[rod]
length = 1.0
B1 = "1 + 0.5*s"
B2 = 1.5
B3 = "0.8 - 0.2*s"
extensible = true
A1 = 30.0
A2 = "40 + 10*s"
A3 = 50.0
u_hat = [1.0, -0.3, 0.5]
v_hat = [0.05, -0.02, 1.03]
[start]
type = "clamped"
position = [0, 0, 0]
[end]
type = "loaded"
force = [2.0, -0.5, -1.0]
moment = [0.1, 0.2, 0.3]
[guess]
force = [-2.0, 0.5, 1.0]
)",
                                         "spatial_extensible.toml");
  const Case twisted = load_case(testing::case_path("twisted_clamped.toml"),
                                 {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}}, "axial");
  for (const Case& c : {twisted, extensible}) {
    SCOPED_TRACE(c.path);
    expect_loose_jacobian_within(c, 0.05, 1e-5);
    const ShootingProblem problem(c.definition);
    expect_jacobians_agree(problem, perturbed_guess(problem, c, 0.05));
  }
}

// dF/d(parameter) where one side of the central difference is no rod: at EI = 5e-7 the step
// h = 1e-6 (1 + EI) probes EI - h < 0 (as a homotopy from EI = 1 to 2e11 probes its start at
// t - h). That failed the derivative, and with it the homotopy's start; it is now the forward
// difference, (F(EI + h) - F(EI)) / h, the same numbers as formed here from two residuals.
TEST(ParameterDerivative, OneSidedWhereTheOtherSideIsNoRod) {
  const double EI = 5e-7, h = 1e-6 * (1.0 + EI);
  const Case c = load_case(testing::case_path("simply_supported.toml"), {{"EI", EI}});
  ShootingProblem problem(c.definition);
  const Eigen::VectorXd x = perturbed_guess(problem, c, 0.01);
  Eigen::VectorXd dF, F0, Fp;
  std::string failure;
  ASSERT_TRUE(problem.parameter_derivative(x, "EI", &dF, &failure)) << failure;
  ASSERT_TRUE(problem.evaluate(x, &F0, nullptr, &failure)) << failure;
  ShootingProblem plus = problem;
  plus.set_parameter("EI", EI + h);
  ASSERT_TRUE(plus.evaluate(x, &Fp, nullptr, &failure)) << failure;
  const Eigen::VectorXd forward = (Fp - F0) / h;
  EXPECT_LE((dF - forward).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, forward.cwiseAbs().maxCoeff()));
  // And where both sides are rods, the central difference as before.
  ShootingProblem stiff = problem;
  stiff.set_parameter("EI", 1.0);
  ASSERT_TRUE(stiff.parameter_derivative(x, "EI", &dF, &failure)) << failure;
  EXPECT_TRUE(dF.allFinite());
}

}  // namespace
}  // namespace kirchhoff
