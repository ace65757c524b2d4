#include "kirchhoff/jacobian_lu.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kirchhoff {

JacobianLU::JacobianLU(const Eigen::MatrixXd& M) {
  const Eigen::Index n = M.rows();
  const Eigen::Index nonzeros = n >= kSparseFrom ? (M.array() != 0.0).count() : n * n;
  if (nonzeros <= kSparseDensity * static_cast<double>(n * n)) {
    sparse_ = std::make_unique<Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>>>();
    const Eigen::SparseMatrix<double> S = M.sparseView(1.0, 0.0);
    sparse_->compute(S);
    ok_ = sparse_->info() == Eigen::Success;
    rcond_ = ok_ ? estimate_reciprocal_condition(M) : 0.0;
    return;
  }
  dense_.compute(M);
  ok_ = true;
  const Eigen::VectorXd pivots = dense_.matrixLU().diagonal().cwiseAbs();
  const double largest = n > 0 ? pivots.maxCoeff() : 0.0;
  rcond_ = largest > 0 ? std::min(dense_.rcond(), pivots.minCoeff() / largest) : 0.0;
}

Eigen::VectorXd JacobianLU::solve(const Eigen::VectorXd& b) const {
  if (sparse_) return sparse_->solve(b);
  return dense_.solve(b);
}

Eigen::VectorXd JacobianLU::solve_transposed(const Eigen::VectorXd& b) const {
  return sparse_->transpose().solve(b);
}

double JacobianLU::determinant() const {
  if (!ok_) return 0.0;
  if (!sparse_) return dense_.determinant();
  const double log_abs = std::min(sparse_->logAbsDeterminant(), std::log(std::numeric_limits<double>::max()));
  return sparse_->signDeterminant() * std::exp(log_abs);
}

// Hager's estimate of |M^-1|_1 (as LAPACK's dgecon and Eigen's dense rcond use), with solves by
// the sparse factors: a handful of solves instead of forming the inverse.
double JacobianLU::estimate_reciprocal_condition(const Eigen::MatrixXd& M) const {
  const Eigen::Index n = M.rows();
  const double norm_M = M.cwiseAbs().colwise().sum().maxCoeff();
  if (!(norm_M > 0)) return 0.0;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(n, 1.0 / static_cast<double>(n));
  double estimate = 0.0;
  for (int it = 0; it < 5; ++it) {
    const Eigen::VectorXd y = solve(x);
    if (!y.allFinite()) return 0.0;
    estimate = std::max(estimate, y.lpNorm<1>());
    const Eigen::VectorXd z = solve_transposed(y.unaryExpr([](double v) { return v >= 0 ? 1.0 : -1.0; }));
    Eigen::Index j;
    const double largest = z.cwiseAbs().maxCoeff(&j);
    if (largest <= z.dot(x)) break;
    x.setZero();
    x[j] = 1.0;
  }
  return estimate > 0 ? 1.0 / (norm_M * estimate) : 0.0;
}

}  // namespace kirchhoff
