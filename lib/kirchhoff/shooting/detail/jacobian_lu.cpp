#include "kirchhoff/shooting/detail/jacobian_lu.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace kirchhoff {

namespace {

// 1 / v of each largest |entry| v, 1 where a row or column is zero: the equilibrating scales.
Eigen::VectorXd reciprocals_or_one(const Eigen::VectorXd& maxima) {
  return maxima.unaryExpr([](double v) { return v > 0 ? 1.0 / v : 1.0; });
}

// The largest number of non-zeros in one row and in one column of a sparse matrix.
struct DensestLines {
  Eigen::Index row = 0, column = 0;
};

// [top; bottom^T] (bottom empty: top alone) scaled by rows, as a compressed sparse matrix, built in
// one pass over top in its storage order; the row maxima (the scaling) are applied to the values
// afterwards. nullopt when more than kSparseDensity of the entries are non-zero. The Jacobians of
// long rods are tens of megabytes dense: neither the bordered nor the scaled matrix is formed.
std::optional<Eigen::SparseMatrix<double>> sparse_bordered(const Eigen::MatrixXd& top, const Eigen::VectorXd& bottom,
                                                           double density, Eigen::VectorXd* row_scale,
                                                           DensestLines* densest) {
  const Eigen::Index rows = top.rows() + (bottom.size() > 0 ? 1 : 0), cols = top.cols();
  const auto allowed = static_cast<Eigen::Index>(density * static_cast<double>(rows * cols));
  Eigen::VectorXd row_max = Eigen::VectorXd::Zero(rows);
  std::vector<Eigen::Index> row_count(static_cast<size_t>(rows), 0);
  Eigen::SparseMatrix<double> S(rows, cols);
  // All the room the sparse path may use, at once: insertBack grows the storage one entry at a
  // time past its capacity (quadratic), and untouched capacity costs no more than its address space.
  S.reserve(allowed + 1);
  Eigen::Index nonzeros = 0;
  for (Eigen::Index j = 0; j < cols; ++j) {
    const Eigen::Index column_start = nonzeros;
    S.startVec(j);
    const double* column = top.col(j).data();
    for (Eigen::Index i = 0; i < top.rows(); ++i)
      if (const double v = column[i]; v != 0.0) {
        S.insertBack(i, j) = v;
        row_max[i] = std::max(row_max[i], std::abs(v));
        ++row_count[static_cast<size_t>(i)];
        ++nonzeros;
      }
    if (bottom.size() > 0 && bottom[j] != 0.0) {
      S.insertBack(rows - 1, j) = bottom[j];
      row_max[rows - 1] = std::max(row_max[rows - 1], std::abs(bottom[j]));
      ++row_count[static_cast<size_t>(rows - 1)];
      ++nonzeros;
    }
    if (nonzeros > allowed) return std::nullopt;
    densest->column = std::max(densest->column, nonzeros - column_start);
  }
  S.finalize();
  densest->row = *std::max_element(row_count.begin(), row_count.end());
  *row_scale = reciprocals_or_one(row_max);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(S, j); it; ++it) it.valueRef() *= (*row_scale)[it.row()];
  return S;
}

Eigen::VectorXd column_maxima(const Eigen::SparseMatrix<double>& S) {
  Eigen::VectorXd maxima = Eigen::VectorXd::Zero(S.cols());
  for (Eigen::Index j = 0; j < S.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(S, j); it; ++it)
      maxima[j] = std::max(maxima[j], std::abs(it.value()));
  return maxima;
}

Eigen::MatrixXd stacked(const Eigen::MatrixXd& top, const Eigen::VectorXd& bottom) {
  if (bottom.size() == 0) return top;
  Eigen::MatrixXd M(top.rows() + 1, top.cols());
  M << top, bottom.transpose();
  return M;
}

}  // namespace

JacobianLU::JacobianLU(const Eigen::MatrixXd& M) : JacobianLU(M, Eigen::VectorXd()) {}

bool JacobianLU::sparse_enough(const Eigen::MatrixXd& M) {
  if (M.rows() < kSparseFrom) return false;
  const auto allowed = static_cast<Eigen::Index>(kSparseDensity * static_cast<double>(M.size()));
  return (M.array() != 0.0).count() <= allowed;
}

JacobianLU::JacobianLU(const Eigen::MatrixXd& top, const Eigen::VectorXd& bottom) {
  // Rows of large matrices are equilibrated first: residuals of forces (~1e4 on a tight
  // plectoneme) sit beside residuals of positions and quaternions (~1), and unscaled, that spread
  // alone made the condition estimate of a well-posed corrector matrix fall below the singularity
  // threshold. Small matrices are factorised as they come: they are well scaled, and the planar
  // contact continuations (the hanging fold) follow branches so close to branch points that
  // rounding of another pivot sequence sent them onto the asymmetric branch.
  const Eigen::Index n = top.rows() + (bottom.size() > 0 ? 1 : 0);
  row_scale_ = Eigen::VectorXd::Ones(n);
  if (n >= kSparseFrom) {
    DensestLines densest;
    if (auto S = sparse_bordered(top, bottom, kSparseDensity, &row_scale_, &densest)) {
      sparse_ = std::make_unique<Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>>>();
      // A dense row (the continuation's tangent row t^T) is one partial pivoting may choose as a
      // pivot wherever its entry beats the column's others, and each time it spreads into the rows
      // below: on the exact ply at L/2R = 1000 (4,237 unknowns, 47,000 non-zeros) the factors held
      // 2.0 million entries. Dense columns (the unknown parameters) COLAMD orders last, where they
      // cost little. So a matrix whose densest row outweighs its densest column is factorised
      // transposed, its dense row becoming a column: 0.46 million entries there, a third of the
      // time, and a smaller residual. Newton's matrices, with dense columns only, are not.
      transposed_ = densest.row > densest.column;
      if (transposed_) {
        // Partial pivoting on the transpose compares entries along a row of M, across its
        // unknowns, whose scales differ by orders (forces ~1e4 beside positions ~1e-3 on a
        // plectoneme): the columns are equilibrated too. (Unequilibrated, a plectoneme barrier
        // branch's H_A - H_B grew past 1e-8.)
        column_scale_ = reciprocals_or_one(column_maxima(*S));
        const Eigen::SparseMatrix<double> T = (*S * column_scale_.asDiagonal()).transpose();
        sparse_->compute(T);
      } else {
        sparse_->compute(*S);
      }
      ok_ = sparse_->info() == Eigen::Success;
      rcond_ = ok_ ? estimate_reciprocal_condition(one_norm(*S)) : 0.0;
      if (rcond_ > 0.0) return;
      // Sparse LU pivots within a column of the fill-reducing order; where that meets an exact
      // zero the dense LU, free to pivot over the whole column, decides whether M is singular.
      sparse_.reset();
      transposed_ = false;
    }
    const Eigen::MatrixXd M = stacked(top, bottom);
    row_scale_ = reciprocals_or_one(M.cwiseAbs().rowwise().maxCoeff());
    dense_.compute(row_scale_.asDiagonal() * M);
  } else {
    dense_.compute(stacked(top, bottom));
  }
  ok_ = true;
  const Eigen::VectorXd pivots = dense_.matrixLU().diagonal().cwiseAbs();
  const double largest = n > 0 ? pivots.maxCoeff() : 0.0;
  rcond_ = largest > 0 ? std::min(dense_.rcond(), pivots.minCoeff() / largest) : 0.0;
}

double JacobianLU::one_norm(const Eigen::SparseMatrix<double>& S) {
  double largest = 0.0;
  for (Eigen::Index j = 0; j < S.outerSize(); ++j) {
    double column = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(S, j); it; ++it) column += std::abs(it.value());
    largest = std::max(largest, column);
  }
  return largest;
}

Eigen::VectorXd JacobianLU::solve(const Eigen::VectorXd& b) const { return solve_scaled(row_scale_.cwiseProduct(b)); }

Eigen::VectorXd JacobianLU::solve_scaled(const Eigen::VectorXd& b) const {
  if (!sparse_) return dense_.solve(b);
  // S = D_r M = S' D_c^-1 with S' the matrix factorised transposed: S^-1 b = D_c S'^-1 b.
  if (transposed_) return column_scale_.cwiseProduct(sparse_->transpose().solve(b));
  return sparse_->solve(b);
}

Eigen::VectorXd JacobianLU::solve_transposed(const Eigen::VectorXd& b) const {
  if (transposed_) return sparse_->solve(column_scale_.cwiseProduct(b));  // S^-T b = S'^-T D_c b
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
  if (transposed_) log_abs -= column_scale_.array().log().sum();
  return sign * std::exp(std::clamp(log_abs, -700.0, 700.0));
}

// Hager's estimate of |M^-1|_1 (as LAPACK's dgecon and Eigen's dense rcond use), with solves by
// the sparse factors: a handful of solves instead of forming the inverse.
double JacobianLU::estimate_reciprocal_condition(double norm_M) const {
  const Eigen::Index n = row_scale_.size();
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
