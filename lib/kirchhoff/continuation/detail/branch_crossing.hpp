#pragma once
// The two branches through a simple branch point, from the algebraic bifurcation equation.
//
// At a simple branch point z of F(z) = 0 (z = (x, lambda), F: R^{n+1} -> R^n) the matrix
// A = F'(z) has rank n - 1: its null space is two-dimensional, spanned by phi1 and phi2, and one
// left null vector psi. Every branch through z leaves it along a tangent v = a phi1 + b phi2 with
//   psi . F''(z)[v, v] = B11 a^2 + 2 B12 a b + B22 b^2 = 0,
// whose two real roots (B12^2 > B11 B22 at a transversal crossing) are the two branches'
// tangents (Keller 1977; Seydel, "Practical Bifurcation and Stability Analysis", 5.6). The
// second derivatives come from central differences of F along the null vectors.
//
// Why not the null vector orthogonal to the arriving tangent: a branch point's bordered tangent
// is the solution of a singular system, so its component along the second null vector is the
// matrix's error over its tiny singular value, of order one (a disc contact's pitchfork: the
// tangent came out along the bifurcating branch and switching went back along the old one).
// And where the branches cross at an angle other than 90 degrees (every transcritical point, and
// pitchforks whose symmetry does not act orthogonally on the unknowns) the orthogonal
// complement is not the other branch's tangent.

#include <Eigen/Dense>
#include <functional>
#include <optional>

namespace kirchhoff::detail {

// F at z; false where it cannot be evaluated.
using ResidualAt = std::function<bool(const Eigen::VectorXd& z, Eigen::VectorXd* F)>;

struct BranchCrossing {
  Eigen::VectorXd arriving;  // unit tangent of the branch closest to `arrival`, oriented along it
  Eigen::VectorXd leaving;   // unit tangent of the other branch (its orientation is the caller's)
};

// The null space of A (n x (n+1)) where it is two-dimensional: its smallest singular value below
// `singular_tolerance` of its largest, the one before above it.
struct NullSpace {
  Eigen::VectorXd phi1, phi2;  // orthonormal right null vectors
  Eigen::VectorXd psi;         // the unit left null vector
};
std::optional<NullSpace> two_dimensional_null_space(const Eigen::MatrixXd& A, double singular_tolerance);

// `arrival` projected onto that null space, normalised: a branch point's tangent from the regular
// point before it, within O(step x curvature) of the arriving branch's (closer to it than to the
// other branch's wherever the step resolves the branch), for branch_crossing to pick the arriving
// root by. Empty where the null space is not two-dimensional.
std::optional<Eigen::VectorXd> arrival_in_null_space(const Eigen::MatrixXd& A, const Eigen::VectorXd& arrival,
                                                     double singular_tolerance);

// The two branches' tangents at z, where A = F'(z) (n x (n+1)) has a two-dimensional null space
// (its smallest singular value below `singular_tolerance` of its largest, the one before above
// it). `arrival` picks which root is the branch arrived on (the tangent of a regular point
// before z on it). Empty where the null space is not two-dimensional, the quadratic has no two
// distinct real roots above its differencing noise, or F cannot be evaluated.
std::optional<BranchCrossing> branch_crossing(const Eigen::MatrixXd& A, const ResidualAt& residual,
                                              const Eigen::VectorXd& z, const Eigen::VectorXd& arrival,
                                              double singular_tolerance);

}  // namespace kirchhoff::detail
