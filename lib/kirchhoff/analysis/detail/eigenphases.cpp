#include "kirchhoff/analysis/detail/eigenphases.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>

namespace kirchhoff::detail {
namespace {

// Fixed capacity (the full frame of a spatial rod is 12 x 6): no allocation at each of the
// index's steps.
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 6>;
using SmallComplex = Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

// A residual |W v - e^(i theta) v| above this (W unitary, v a unit vector) means the combination's
// eigenvector mixed two of W's: round-off leaves ~1e-15 where it did not.
constexpr double kMixedResidual = 1e-9;

double wrap(double angle) { return std::remainder(angle, 2 * M_PI); }

// [U; P] with orthonormal columns spanning the same plane.
Small orthonormal_frame(const Eigen::MatrixXd& U, const Eigen::MatrixXd& P, bool orthonormal) {
  const Eigen::Index m = U.cols();
  Small Q(2 * m, m);
  Q << U, P;
  if (!orthonormal) {
    const Eigen::HouseholderQR<Small> qr(Q);
    Q.setIdentity(2 * m, m);
    Q.applyOnTheLeft(qr.householderQ());
  }
  return Q;
}

// The eigenphases from real symmetric eigenproblems of order M (see eigenphases.hpp), Q = [U; P]
// orthonormal; false where every combination mixed two of W's eigenvectors.
template <int M>
bool real_eigenphases(const Small& Q, Eigen::VectorXd* phase) {
  using Mat = Eigen::Matrix<double, M, M>;
  const Mat U = Q.topRows(M), P = Q.bottomRows(M);
  const Mat C = U * U.transpose() - P * P.transpose();
  Mat S = U * P.transpose();
  S += S.transpose().eval();
  // Angles spread so that no two eigenphase pairs are likely symmetric about more than one.
  for (const double a : {0.3183098861837907, 2.0943951023931957, -1.1071487177940904}) {
    const Eigen::SelfAdjointEigenSolver<Mat> solver(std::cos(a) * C + std::sin(a) * S);
    if (solver.info() != Eigen::Success) continue;
    const Mat& V = solver.eigenvectors();
    bool mixed = false;
    for (int j = 0; j < M && !mixed; ++j) {
      const Eigen::Matrix<double, M, 1> Cv = C * V.col(j), Sv = S * V.col(j);
      const double c = V.col(j).dot(Cv), s = V.col(j).dot(Sv);
      mixed = std::sqrt((Cv - c * V.col(j)).squaredNorm() + (Sv - s * V.col(j)).squaredNorm()) > kMixedResidual;
      (*phase)[j] = std::atan2(s, c);
    }
    if (!mixed) return true;
  }
  return false;
}

}  // namespace

Eigen::VectorXd eigenphases_by_complex_schur(const Eigen::MatrixXd& U, const Eigen::MatrixXd& P, bool orthonormal) {
  const Eigen::Index m = U.cols();
  Eigen::VectorXd phase(m);
  if (m == 0) return phase;
  const Small Q = orthonormal_frame(U, P, orthonormal);
  const SmallComplex X = Q.topRows(m).cast<std::complex<double>>() + std::complex<double>(0, 1) * Q.bottomRows(m);
  const SmallComplex W = X * X.transpose();
  Eigen::ComplexEigenSolver<SmallComplex> solver(W, false);
  for (Eigen::Index j = 0; j < m; ++j) phase[j] = std::arg(solver.eigenvalues()[j]);
  return phase;
}

Eigen::VectorXd eigenphases(const Eigen::MatrixXd& U, const Eigen::MatrixXd& P, bool orthonormal) {
  const Eigen::Index m = U.cols();
  Eigen::VectorXd phase(m);
  if (m == 0) return phase;
  if (m == 1) {  // W = (u + ip)^2 / (u^2 + p^2)
    phase[0] = wrap(2 * std::atan2(P(0, 0), U(0, 0)));
    return phase;
  }
  const Small Q = orthonormal_frame(U, P, orthonormal);
  bool found = false;
  switch (m) {  // fixed sizes: Eigen's fixed-size kernels cost a fraction of its dynamic ones here
    case 2: found = real_eigenphases<2>(Q, &phase); break;
    case 3: found = real_eigenphases<3>(Q, &phase); break;
    case 4: found = real_eigenphases<4>(Q, &phase); break;
    case 5: found = real_eigenphases<5>(Q, &phase); break;
    case 6: found = real_eigenphases<6>(Q, &phase); break;
    default: break;
  }
  return found ? phase : eigenphases_by_complex_schur(U, P, orthonormal);
}

}  // namespace kirchhoff::detail
