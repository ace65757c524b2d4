#pragma once
// LU factorisation of the matrices Newton and the continuation corrector solve with.

#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <memory>

namespace kirchhoff {

// Multiple shooting makes these matrices block-bidiagonal (one state-sized block per segment and
// its matching identity) with a few dense rows and columns (boundary conditions, unknown
// parameters, the continuation parameter and the arclength row). A dense LU costs
// O((segments * state)^3) and dominated long multiple-shooting runs; a sparse LU costs
// O(segments * state^3). Large matrices that are mostly zeros are therefore factorised as sparse
// (COLAMD ordering; transposed when a dense row, such as the continuation's tangent row, would
// otherwise spread through the factors); small or dense ones by partial-pivoting dense LU.
class JacobianLU {
 public:
  explicit JacobianLU(const Eigen::MatrixXd& M);
  // The bordered matrix [top; bottom^T] (the continuation's [F_x F_lambda; t^T]) without forming it.
  JacobianLU(const Eigen::MatrixXd& top, const Eigen::VectorXd& bottom);

  // Whether M is large and sparse enough for the sparse path (kSparseFrom, kSparseDensity): a
  // caller with a dense LU of its own need not have this class repeat it.
  static bool sparse_enough(const Eigen::MatrixXd& M);

  // False when the factorisation broke down (an exactly singular sparse matrix).
  bool ok() const { return ok_; }
  bool sparse() const { return sparse_ != nullptr; }
  bool transposed() const { return transposed_; }  // sparse factors of M^T (a dense row)
  // 1 / cond_1 estimate (of the row-equilibrated matrix when large); for dense matrices also at most the
  // smallest pivot over the largest (a cheap guard that the estimate alone can miss). 0 when the
  // factorisation failed.
  double reciprocal_condition() const { return rcond_; }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Sign-faithful determinant; its magnitude is clamped to the double range (only the sign and
  // order of magnitude serve, as a branch-point test function).
  double determinant() const;

  // Matrices at least this large, with at most kSparseDensity of their entries non-zero, go sparse.
  static constexpr int kSparseFrom = 96;
  static constexpr double kSparseDensity = 0.15;

 private:
  // Solves with the row-scaled matrix S = row_scale M and with its transpose, whichever factors
  // are kept.
  Eigen::VectorXd solve_scaled(const Eigen::VectorXd& b) const;
  Eigen::VectorXd solve_transposed(const Eigen::VectorXd& b) const;
  // Of the factorised (row-scaled) matrix, whose 1-norm is norm_M.
  double estimate_reciprocal_condition(double norm_M) const;
  static double one_norm(const Eigen::SparseMatrix<double>& S);

  Eigen::VectorXd row_scale_;  // 1 / largest |entry| of each row
  bool ok_ = false;
  // The sparse factors are those of (row_scale M column_scale)^T, the columns equilibrated too.
  bool transposed_ = false;
  Eigen::VectorXd column_scale_;
  double rcond_ = 0.0;
  Eigen::PartialPivLU<Eigen::MatrixXd> dense_;
  std::unique_ptr<Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>>> sparse_;
};

}  // namespace kirchhoff
