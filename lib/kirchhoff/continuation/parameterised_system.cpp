#include "kirchhoff/continuation/parameterised_system.hpp"

#include <cmath>
#include <sstream>

#include "kirchhoff/shooting/newton.hpp"

namespace kirchhoff {

FixedParameterSolve ParameterisedSystem::solve_at(const Eigen::VectorXd& x0, double lambda, double tolerance) {
  constexpr int kMaxIterations = 50;
  FixedParameterSolve out;
  out.x = x0;
  Eigen::VectorXd F;
  Eigen::MatrixXd A;
  std::string failure;
  for (int it = 0;; ++it) {
    if (!matrix(out.x, lambda, &F, &A, &failure, false)) {
      out.report = "cannot be evaluated: " + failure;
      return out;
    }
    out.residual_norm = max_abs_or_nan(F);
    if (out.residual_norm <= tolerance) {
      out.converged = true;
      out.report = "converged after " + std::to_string(it) + " Newton iterations";
      return out;
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(A.leftCols(size()));
    if (!std::isfinite(out.residual_norm) || it == kMaxIterations || !lu.isInvertible()) {
      std::ostringstream why;
      why << "Newton did not converge (max |F| = " << out.residual_norm << " after " << it << " iterations"
          << (lu.isInvertible() ? "" : ", singular F_x") << ")";
      out.report = why.str();
      return out;
    }
    out.x -= lu.solve(F);
  }
}

}  // namespace kirchhoff
