#include "kirchhoff/jacobian_lu.hpp"

#include <algorithm>
#include <cmath>

namespace kirchhoff {

JacobianLU::JacobianLU(const Eigen::MatrixXd& unscaled) {
  // Rows of large matrices are equilibrated first: residuals of forces (~1e4 on a tight
  // plectoneme) sit beside residuals of positions and quaternions (~1), and unscaled, that spread
  // alone made the condition estimate of a well-posed corrector matrix fall below the singularity
  // threshold. Small matrices are factorised as they come: they are well scaled, and the planar
  // contact continuations (the hanging fold) follow branches so close to branch points that
  // rounding of another pivot sequence sent them onto the asymmetric branch.
  const Eigen::Index n = unscaled.rows();
  row_scale_ = Eigen::VectorXd::Ones(n);
  if (n >= kSparseFrom)
    row_scale_ = unscaled.cwiseAbs().rowwise().maxCoeff().unaryExpr([](double v) { return v > 0 ? 1.0 / v : 1.0; });
  const Eigen::MatrixXd M = row_scale_.asDiagonal() * unscaled;
  const Eigen::Index nonzeros = n >= kSparseFrom ? (M.array() != 0.0).count() : n * n;
  if (nonzeros <= kSparseDensity * static_cast<double>(n * n)) {
    sparse_ = std::make_unique<Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>>>();
    const Eigen::SparseMatrix<double> S = M.sparseView(1.0, 0.0);
    sparse_->compute(S);
    ok_ = sparse_->info() == Eigen::Success;
    rcond_ = ok_ ? estimate_reciprocal_condition(M) : 0.0;
    if (rcond_ > 0.0) return;
    // Sparse LU pivots within a column of the fill-reducing order; where that meets an exact zero
    // the dense LU, free to pivot over the whole column, decides whether M is singular.
    sparse_.reset();
  }
  dense_.compute(M);
  ok_ = true;
  const Eigen::VectorXd pivots = dense_.matrixLU().diagonal().cwiseAbs();
  const double largest = n > 0 ? pivots.maxCoeff() : 0.0;
  rcond_ = largest > 0 ? std::min(dense_.rcond(), pivots.minCoeff() / largest) : 0.0;
}

Eigen::VectorXd JacobianLU::solve(const Eigen::VectorXd& b) const { return solve_scaled(row_scale_.cwiseProduct(b)); }

Eigen::VectorXd JacobianLU::solve_scaled(const Eigen::VectorXd& b) const {
  if (sparse_) return sparse_->solve(b);
  return dense_.solve(b);
}

Eigen::VectorXd JacobianLU::solve_transposed(const Eigen::VectorXd& b) const {
  return sparse_->transpose().solve(b);
}

double JacobianLU::determinant() const {
  if (!ok_) return 0.0;
  double sign = 1.0, log_abs = 0.0;
  if (sparse_) {
    sign = sparse_->signDeterminant();
    log_abs = sparse_->logAbsDeterminant();
  } else {
    const Eigen::VectorXd pivots = dense_.matrixLU().diagonal();
    sign = dense_.permutationP().determinant();
    for (const double u : pivots) {
      if (u == 0.0) return 0.0;
      sign *= u < 0 ? -1.0 : 1.0;
      log_abs += std::log(std::abs(u));
    }
  }
  log_abs -= row_scale_.array().log().sum();  // det of the unscaled matrix
  return sign * std::exp(std::clamp(log_abs, -700.0, 700.0));
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
    const Eigen::VectorXd y = solve_scaled(x);
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
