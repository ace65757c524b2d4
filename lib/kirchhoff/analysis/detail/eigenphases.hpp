// The eigenphases of a Lagrangian frame: the angles the stability index follows along the rod
// (stability.cpp), one per Jacobi field, passing odd multiples of pi at conjugate points.
#pragma once

#include <Eigen/Dense>

namespace kirchhoff::detail {

// Eigenphases in (-pi, pi] of W = (U + iP)(U - iP)^-1 for the m x m blocks U, P of a Lagrangian
// frame (U^T P symmetric, [U; P] of full rank), m <= 6. `orthonormal`: [U; P] has orthonormal
// columns already; otherwise they are made so first (a QR factorisation, which leaves W as it is).
// In no particular order.
//
// With [U; P] orthonormal, X = U + iP is unitary and W = X X^T = C + iS with C = U U^T - P P^T
// and S = U P^T + P U^T real, symmetric and commuting: W's eigenvectors can be taken real, and
// they are those of cos(a) C + sin(a) S for any a at which that combination's eigenvalues,
// cos(theta_j - a), are distinct where W's are. Each eigenphase is then the angle of
// v^T C v + i v^T S v. Where two different eigenphases lie symmetrically about a (the
// combination's eigenvalue double, its eigenvectors mixing theirs) the residual of
// W v = e^(i theta) v shows it, and another a is tried; after three, the complex eigensolver of W
// (Schur's). A real symmetric eigenproblem of order m costs about a third of the complex one
// (3.3 against 10.2 thousand instructions on the twisted rod's 3 x 3 frames).
Eigen::VectorXd eigenphases(const Eigen::MatrixXd& U, const Eigen::MatrixXd& P, bool orthonormal);

// The same by the complex eigensolver of W alone: the reference the tests compare with.
Eigen::VectorXd eigenphases_by_complex_schur(const Eigen::MatrixXd& U, const Eigen::MatrixXd& P, bool orthonormal);

}  // namespace kirchhoff::detail
