// The sparse path of JacobianLU must give what the dense LU gives on the matrices multiple
// shooting makes: block-bidiagonal with dense border rows and columns.
#include "kirchhoff/shooting/detail/jacobian_lu.hpp"

#include <gtest/gtest.h>

#include <random>

namespace kirchhoff {
namespace {

// Segments of `block` states: Phi_i in the diagonal block column, -I beside it, boundary rows
// and a dense parameter column and arclength row, as Continuation's bordered matrix. Each Phi
// is near the identity, as the flow over a short segment is (random blocks would make the
// chain's condition number grow exponentially with the segments).
Eigen::MatrixXd multiple_shooting_like(int segments, int block, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  const int n = segments * block + 1;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i + 1 < segments; ++i) {
    for (int r = 0; r < block; ++r)
      for (int c = 0; c < block; ++c) M(i * block + r, i * block + c) = (r == c ? 1.0 : 0.0) + 0.3 * normal(gen);
    M.block(i * block, (i + 1) * block, block, block) = -Eigen::MatrixXd::Identity(block, block);
  }
  const int bc = (segments - 1) * block;  // start and end conditions: half the state at each end
  for (int r = 0; r < block / 2; ++r) M(bc + r, r) = 1.0;
  for (int r = block / 2; r < block; ++r)
    for (int c = 0; c < block; ++c) M(bc + r, (segments - 1) * block + c) = normal(gen);
  for (int r = 0; r < n; ++r) M(r, n - 1) = normal(gen);
  for (int c = 0; c < n; ++c) M(n - 1, c) = normal(gen);
  return M;
}

// lu (of M) solves, estimates the condition and gives the determinant as the dense LU of M.
void expect_as_the_dense_lu(const JacobianLU& lu, const Eigen::MatrixXd& M) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> dense(M);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(M.rows(), -1.0, 2.0);
  const Eigen::VectorXd x = lu.solve(b), x_dense = dense.solve(b);
  // Both are backward stable: they agree to cond(M) * eps.
  const double cond = 1.0 / dense.rcond();
  EXPECT_LE((x - x_dense).norm() / x_dense.norm(), 100.0 * cond * 1e-16);
  EXPECT_LE((M * x - b).norm() / b.norm(), 1e-13);
  // Hager's estimate is a lower bound of |M^-1|_1 that is rarely off by more than a few.
  EXPECT_GT(lu.reciprocal_condition(), 0.99 * dense.rcond() / 10.0);
  EXPECT_LT(lu.reciprocal_condition(), 10.0 * dense.rcond());
  EXPECT_NEAR(lu.determinant() / dense.determinant(), 1.0, 1e-9);
}

TEST(JacobianLU, SparsePathSolvesAsTheDenseLU) {
  const Eigen::MatrixXd M = multiple_shooting_like(20, 14, 1);
  const JacobianLU lu(M);
  ASSERT_TRUE(lu.sparse());
  ASSERT_TRUE(lu.ok());
  expect_as_the_dense_lu(lu, M);
}

// The continuation's bordered matrix [F_x F_lambda; t^T]: its tangent row is its densest line (the
// parameter column is dense only in some rows, as a plectoneme's contact parameters), so its
// factors are those of the transpose; the solution, condition estimate and determinant are the
// matrix's own. Its columns of very different scales (forces beside positions) are equilibrated
// for the transpose's pivoting. Newton's matrix alone (no tangent row) is factorised as it is.
TEST(JacobianLU, BorderedMatrixWithADenseRowIsFactorisedTransposed) {
  Eigen::MatrixXd M = multiple_shooting_like(20, 14, 4);
  const Eigen::Index n = M.rows();
  M.col(n - 1).tail(n / 2).setZero();
  for (Eigen::Index j = 0; j < n; j += 10) M.col(j) *= 1e4;  // (every 10th: the determinant stays finite)
  const JacobianLU lu(M.topRows(n - 1), M.row(n - 1).transpose());
  ASSERT_TRUE(lu.ok());
  ASSERT_TRUE(lu.transposed());
  // The condition estimate is still of the 1-norm of M^-1 (its solves swapped), not of M^-T.
  expect_as_the_dense_lu(lu, M);

  const JacobianLU newton(M.topLeftCorner(n - 1, n - 1));
  ASSERT_TRUE(newton.sparse());
  EXPECT_FALSE(newton.transposed());
}

TEST(JacobianLU, SmallOrDenseMatricesStayDense) {
  EXPECT_FALSE(JacobianLU(multiple_shooting_like(3, 14, 2)).sparse());
  EXPECT_FALSE(JacobianLU(Eigen::MatrixXd::Random(200, 200)).sparse());
}

TEST(JacobianLU, SingularSparseMatrixIsReported) {
  Eigen::MatrixXd M = multiple_shooting_like(20, 14, 3);
  M.row(5).setZero();
  const JacobianLU lu(M);
  EXPECT_TRUE(!lu.ok() || lu.reciprocal_condition() < 1e-15);
}

}  // namespace
}  // namespace kirchhoff
