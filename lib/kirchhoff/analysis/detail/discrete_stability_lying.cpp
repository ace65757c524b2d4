// The lift-off of a part lying on an obstacle with zero force (see discrete_stability_lying.hpp).
#include "kirchhoff/analysis/detail/discrete_stability_lying.hpp"

#include <Eigen/Eigenvalues>

namespace kirchhoff {

double lift_off_eigenvalue(const Eigen::MatrixXd& Q, const Eigen::MatrixXd& rows, const Eigen::MatrixXd& rates,
                           double h, Eigen::VectorXd* gap_rates) {
  const int m = static_cast<int>(Q.rows());
  // The rows are h times unit normals: singular values O(h) or zero (on a plane the shift along
  // it vanishes identically); 1e-8 h separates them.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(rows, Eigen::ComputeFullV);
  int rank = 0;
  for (int i = 0; i < svd.singularValues().size(); ++i) rank += svd.singularValues()[i] > 1e-8 * h ? 1 : 0;
  const Eigen::MatrixXd Z = svd.matrixV().rightCols(m - rank);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Z.transpose() * Q * Z);
  // Interior nodes weigh h in int dtheta^2.
  *gap_rates = rates * (Z * eig.eigenvectors().col(0));
  return eig.eigenvalues()[0] / h;
}

}  // namespace kirchhoff
