// The shooting Jacobian from the variational equations against central finite differences.
#include "kirchhoff/newton.hpp"
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
                      JacobianCase{"twisted_clamped.toml", {{"phi", 8.0}, {"m_lateral", 0.5}}, "", 2},
                      JacobianCase{"reissner.toml", {}, "", 1},
                      JacobianCase{"reissner.toml", {}, "", 4}),
    [](const ::testing::TestParamInfo<JacobianCase>& info) {
      std::string name = info.param.file;
      name = name.substr(0, name.find('.')) + "_" + std::to_string(info.param.segments) + "seg" +
             (std::string(info.param.phase).empty() ? "" : "_phase") + "_" + std::to_string(info.index);
      return name;
    });

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

}  // namespace
}  // namespace kirchhoff
