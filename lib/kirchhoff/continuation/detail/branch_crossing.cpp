#include "kirchhoff/continuation/detail/branch_crossing.hpp"

#include <array>
#include <cmath>

namespace kirchhoff::detail {
namespace {

// psi . F''(z)[v, v] by the central second difference of step h along v.
std::optional<double> second_derivative(const ResidualAt& residual, const Eigen::VectorXd& z,
                                        const Eigen::VectorXd& F0, const Eigen::VectorXd& psi,
                                        const Eigen::VectorXd& v, double h) {
  Eigen::VectorXd plus, minus;
  if (!residual(z + h * v, &plus) || !residual(z - h * v, &minus)) return std::nullopt;
  return psi.dot(plus + minus - 2.0 * F0) / (h * h);
}

// (B11, B12, B22) of the quadratic form psi . F''[a phi1 + b phi2, same] at step h.
std::optional<std::array<double, 3>> quadratic_form(const ResidualAt& residual, const Eigen::VectorXd& z,
                                                    const Eigen::VectorXd& F0, const Eigen::VectorXd& psi,
                                                    const Eigen::VectorXd& phi1, const Eigen::VectorXd& phi2,
                                                    double h) {
  const auto q11 = second_derivative(residual, z, F0, psi, phi1, h);
  const auto q22 = second_derivative(residual, z, F0, psi, phi2, h);
  const auto q_sum = second_derivative(residual, z, F0, psi, phi1 + phi2, h);
  if (!q11 || !q22 || !q_sum) return std::nullopt;
  return std::array<double, 3>{*q11, 0.5 * (*q_sum - *q11 - *q22), *q22};
}

}  // namespace

std::optional<NullSpace> two_dimensional_null_space(const Eigen::MatrixXd& A, double singular_tolerance) {
  const Eigen::Index n = A.rows();
  if (n < 2 || A.cols() != n + 1) return std::nullopt;
  Eigen::BDCSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (!(s[0] > 0.0) || !(s[n - 1] < singular_tolerance * s[0]) || !(s[n - 2] >= singular_tolerance * s[0]))
    return std::nullopt;
  return NullSpace{svd.matrixV().col(n), svd.matrixV().col(n - 1), svd.matrixU().col(n - 1)};
}

std::optional<Eigen::VectorXd> arrival_in_null_space(const Eigen::MatrixXd& A, const Eigen::VectorXd& arrival,
                                                     double singular_tolerance) {
  const auto null = two_dimensional_null_space(A, singular_tolerance);
  if (!null || arrival.size() != A.cols()) return std::nullopt;
  Eigen::VectorXd t = null->phi1 * null->phi1.dot(arrival) + null->phi2 * null->phi2.dot(arrival);
  if (!(t.norm() > 0.0)) return std::nullopt;
  return t.normalized();
}

std::optional<BranchCrossing> branch_crossing(const Eigen::MatrixXd& A, const ResidualAt& residual,
                                              const Eigen::VectorXd& z, const Eigen::VectorXd& arrival,
                                              double singular_tolerance) {
  const auto null = two_dimensional_null_space(A, singular_tolerance);
  if (!null || z.size() != A.cols() || arrival.size() != A.cols()) return std::nullopt;
  const Eigen::VectorXd& phi1 = null->phi1;
  const Eigen::VectorXd& phi2 = null->phi2;
  const Eigen::VectorXd& psi = null->psi;
  Eigen::VectorXd F0;
  if (!residual(z, &F0)) return std::nullopt;
  // Steps of 1e-3 and 2e-3 along unit null vectors: the rod's residuals vary on scales of order
  // one in their unknowns (angles, arclengths, forces over stiffness), so the truncation error
  // (h^2/12 F'''') is ~1e-7 of the form and the integrator's error (~1e-12 of F, over h^2) ~1e-6.
  // The two steps' forms differ by 3/4 of the larger one's truncation error: where that is not
  // small beside the form, the differences are not to be believed.
  const double h = 1e-3;
  const auto fine = quadratic_form(residual, z, F0, psi, phi1, phi2, h);
  const auto coarse = quadratic_form(residual, z, F0, psi, phi1, phi2, 2.0 * h);
  if (!fine || !coarse) return std::nullopt;
  const auto& [b11, b12, b22] = *fine;
  const double size = std::max({std::abs(b11), std::abs(b12), std::abs(b22)});
  const double disagreement = std::max({std::abs(b11 - (*coarse)[0]), std::abs(b12 - (*coarse)[1]),
                                        std::abs(b22 - (*coarse)[2])});
  if (!(size > 0.0) || !(disagreement < 1e-2 * size)) return std::nullopt;
  // With v = cos(theta) phi1 + sin(theta) phi2 the form is c + r cos(2 theta - phase).
  const double c = 0.5 * (b11 + b22);
  const double r = std::hypot(0.5 * (b11 - b22), b12);
  const double phase = std::atan2(b12, 0.5 * (b11 - b22));
  // Roots closer than the form's differencing error allows telling apart are not two branches.
  if (!(r > 1e-6 * size) || !(std::abs(c) < r * (1.0 - 1e-6))) return std::nullopt;
  const double opening = std::acos(-c / r);
  std::array<Eigen::VectorXd, 2> roots;
  for (int k = 0; k < 2; ++k) {
    const double theta = 0.5 * (phase + (k == 0 ? opening : -opening));
    roots[k] = std::cos(theta) * phi1 + std::sin(theta) * phi2;
  }
  const int closer = std::abs(roots[0].dot(arrival)) >= std::abs(roots[1].dot(arrival)) ? 0 : 1;
  BranchCrossing crossing;
  crossing.arriving = roots[closer] * (roots[closer].dot(arrival) < 0.0 ? -1.0 : 1.0);
  crossing.leaving = roots[1 - closer];
  return crossing;
}

}  // namespace kirchhoff::detail
