// A residual evaluation allocates nothing once the problem's workspace has its buffers
// (ShootingWorkspace::Buffers): counted by interposing malloc, calloc and realloc in this test
// executable (bench/allocation_count.hpp, the count solve_benchmark --summary prints). Not under
// AddressSanitizer, which interposes them itself.
#include <gtest/gtest.h>

#include <string>

#include "../bench/allocation_count.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {
namespace {

// Allocation calls of one residual evaluation (with its variational Jacobian: with_jacobian) at
// the case's solution, after three (the first sizes the buffers) and, with residual_between, a
// residual alone.
long allocations_of_a_residual(const std::string& file, const ParameterOverrides& overrides,
                               const SolverOverrides& solver = {}, bool with_jacobian = false,
                               bool residual_between = false, const std::string& phase_condition = "") {
  const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/" + file, overrides, phase_condition, solver);
  const ShootingProblem problem(c.definition);
  const ShootingResult solved = solve(problem, problem.initial_unknowns(c.start_guess));
  EXPECT_TRUE(solved.summary.converged()) << file;
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  Eigen::MatrixXd* jacobian = with_jacobian ? &J : nullptr;
  std::string failure;
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(problem.evaluate(solved.x, &F, jacobian, &failure)) << failure;
  // (As in a continuation's corrector: residuals alone between two matrices.)
  if (residual_between) EXPECT_TRUE(problem.evaluate(solved.x, &F, nullptr, &failure)) << failure;
  const long before = bench::allocations();
  problem.evaluate(solved.x, &F, jacobian, &failure);
  return bench::allocations() - before;
}

class ResidualAllocationTest : public ::testing::Test {
 protected:
  void SetUp() override {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer interposes malloc itself";
#endif
  }
};

TEST_F(ResidualAllocationTest, PlanarRodAllocatesNothingPerResidual) {
  EXPECT_EQ(allocations_of_a_residual("simply_supported.toml", {{"theta0", 2.0}}), 0);
}

TEST_F(ResidualAllocationTest, SpatialRodAllocatesNothingPerResidual) {
  EXPECT_EQ(allocations_of_a_residual("twisted_clamped.toml", {{"phi", 6.0}}), 0);
  EXPECT_EQ(allocations_of_a_residual("reissner.toml", {}), 0);
}

// Multiple shooting on one thread (fewer than 8 segments): each segment's start and flow reused.
TEST_F(ResidualAllocationTest, MultipleShootingAllocatesNothingPerResidual) {
  EXPECT_EQ(allocations_of_a_residual("simply_supported.toml", {{"theta0", 2.0}}, {{"segments", "4"}}), 0);
}

// With the Jacobian: the end conditions' rows (fixed capacity), the gauge rows and the columns of
// parameters that enter the end conditions only (the workspace's buffers), and each segment's flow
// with its sensitivities (RodEquations::flow_into, into the workspace's sensitivity flows, kept
// apart from the residuals' flows) allocate nothing: on dual numbers (the planar rod's exact
// matrix), written out (the spatial rod's; the planar rod's looser step matrix) and in multiple
// shooting. (It was 36 on the Elastica before the rows and columns were kept, and 3 per segment
// while each flow was returned in new storage.)
TEST_F(ResidualAllocationTest, JacobianAllocatesNothing) {
  EXPECT_EQ(allocations_of_a_residual("simply_supported.toml", {{"theta0", 2.0}}, {}, true), 0);
  EXPECT_EQ(allocations_of_a_residual("simply_supported.toml", {{"theta0", 2.0}}, {{"segments", "4"}}, true), 0);
  EXPECT_EQ(allocations_of_a_residual("simply_supported.toml", {{"theta0", 2.0}}, {{"sensitivity_tol", "1e-8"}}, true),
            0);
  EXPECT_EQ(allocations_of_a_residual("twisted_clamped.toml", {{"phi", 6.0}}, {}, true), 0);
  EXPECT_EQ(allocations_of_a_residual("twisted_clamped.toml", {{"phi", 6.0}}, {{"sensitivity_tol", "1e-8"}}, true), 0);
  EXPECT_EQ(allocations_of_a_residual("heavy_cantilever.toml", {}, {}, true), 0);  // gravity: on dual numbers
  EXPECT_EQ(allocations_of_a_residual("twisted_clamped.toml", {{"phi", 6.0}}, {}, true, true), 0);
  // The buckled rod with the axial phase condition: its unfolding couple, a parameter of the
  // rod's model, has its Jacobian column's plus and minus values built beside x's equations, and
  // the workspace keeps all three (ShootingWorkspace::equations), so a matrix at the same point
  // builds none of them again.
  const ParameterOverrides buckled = {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}};
  EXPECT_EQ(allocations_of_a_residual("twisted_clamped.toml", buckled, {}, true, true, "axial"), 0);
}

}  // namespace
}  // namespace kirchhoff
