// The eigenphases of a Lagrangian frame (analysis/detail/eigenphases.hpp) from a real symmetric
// eigenproblem, against frames built with known eigenphases and against the complex eigensolver
// of W: distinct phases, double ones (an isotropic rod's), pairs placed symmetrically about the
// combination's angles (where its eigenvectors mix), phases at pi (a conjugate point), frames
// not orthonormal.
#include "kirchhoff/analysis/detail/eigenphases.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace kirchhoff {
namespace {

// Distance on the circle.
double circle_distance(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

// Each expected phase is matched to a distinct computed one within `tol`.
void expect_same_phases(const Eigen::VectorXd& computed, std::vector<double> expected, double tol) {
  ASSERT_EQ(computed.size(), static_cast<Eigen::Index>(expected.size()));
  std::vector<bool> used(expected.size(), false);
  for (Eigen::Index j = 0; j < computed.size(); ++j) {
    int best = -1;
    for (size_t k = 0; k < expected.size(); ++k)
      if (!used[k] && (best < 0 || circle_distance(computed[j], expected[k]) < circle_distance(computed[j], expected[best])))
        best = static_cast<int>(k);
    EXPECT_LT(circle_distance(computed[j], expected[best]), tol) << "phase " << computed[j];
    used[best] = true;
  }
}

Eigen::MatrixXd random_orthogonal(int m, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) A(i, j) = normal(rng);
  return Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ();
}

// U = O cos(theta / 2) Q, P = O sin(theta / 2) Q: W = O e^(i theta) O^T whatever the orthogonal Q.
void frame_with_phases(const std::vector<double>& theta, std::mt19937_64& rng, Eigen::MatrixXd* U, Eigen::MatrixXd* P) {
  const int m = static_cast<int>(theta.size());
  const Eigen::MatrixXd O = random_orthogonal(m, rng), Q = random_orthogonal(m, rng);
  Eigen::VectorXd c(m), s(m);
  for (int j = 0; j < m; ++j) c[j] = std::cos(theta[j] / 2), s[j] = std::sin(theta[j] / 2);
  *U = O * c.asDiagonal() * Q;
  *P = O * s.asDiagonal() * Q;
}

// Round-off of an eigenproblem of order <= 6 on entries of order 1: ~1e-14; 1e-11 leaves room
// and still tells a wrong phase (or a mixed pair, off by a finite angle) from a right one.
constexpr double kTol = 1e-11;

TEST(Eigenphases, KnownPhasesAreFoundInEveryCase) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  const double a0 = 0.3183098861837907;  // the first combination's angle (eigenphases.cpp)
  std::vector<std::vector<double>> cases = {
      {0.4, -1.2},
      {M_PI, 0.1, -2.0},                       // a conjugate point
      {1.0, 1.0, -0.5},                        // a double phase (isotropic rod)
      {a0 + 0.7, a0 - 0.7, 2.5},               // symmetric about the first angle: its vectors mix
      {a0 + 0.7, a0 - 0.7, 2.0943951023931957 + 0.2, 2.0943951023931957 - 0.2},  // and about the second
      {M_PI, M_PI, 0.3, -0.3, 2.0, -2.9},      // six, with a double one at pi
  };
  for (int m = 2; m <= 6; ++m)
    for (int r = 0; r < 20; ++r) {
      std::vector<double> theta(m);
      for (double& t : theta) t = angle(rng);
      cases.push_back(theta);
    }
  for (const auto& theta : cases) {
    Eigen::MatrixXd U, P;
    frame_with_phases(theta, rng, &U, &P);
    expect_same_phases(detail::eigenphases(U, P, true), theta, kTol);
    // Not orthonormal: the same plane, scaled and mixed columns.
    const Eigen::MatrixXd G = random_orthogonal(static_cast<int>(theta.size()), rng) * 3.0 +
                              Eigen::MatrixXd::Identity(theta.size(), theta.size());
    expect_same_phases(detail::eigenphases(U * G, P * G, false), theta, kTol);
    const Eigen::VectorXd reference = detail::eigenphases_by_complex_schur(U, P, true);
    expect_same_phases(detail::eigenphases(U, P, true), std::vector<double>(reference.data(), reference.data() + reference.size()),
                       kTol);
  }
}

TEST(Eigenphases, OneFieldIsTwiceItsAngle) {
  Eigen::MatrixXd U(1, 1), P(1, 1);
  U << std::cos(1.2);
  P << std::sin(1.2);
  EXPECT_NEAR(detail::eigenphases(U, P, true)[0], 2.4, 1e-15);
}

}  // namespace
}  // namespace kirchhoff
