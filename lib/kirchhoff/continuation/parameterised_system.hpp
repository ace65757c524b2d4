// What the continuation engine follows: a system F(x, lambda) = 0 of n equations in n unknowns x
// and one parameter lambda, with its matrix [F_x F_lambda]. The engine (continuation.hpp) reaches
// the system through this interface only: a rod's shooting problem is one such system
// (shooting_system.hpp), an algebraic test problem another (tests/continuation_engine_test.cpp).
#pragma once

#include <Eigen/Dense>
#include <string>

namespace kirchhoff {

// A start corrected at fixed lambda (ParameterisedSystem::solve_at).
struct FixedParameterSolve {
  Eigen::VectorXd x;
  bool converged = false;
  double residual_norm = 0.0;  // max |F| at x
  std::string report;          // how it ended, for messages
};

class ParameterisedSystem {
 public:
  virtual ~ParameterisedSystem() = default;

  virtual int size() const = 0;
  // The parameter's starting value (where Continuation::run starts).
  virtual double parameter() const = 0;
  // F(x, lambda). false (with the reason in *failure) where it cannot be evaluated.
  virtual bool residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, std::string* failure) = 0;
  // F(x, lambda) and A = [F_x F_lambda] (n x (n + 1)). With `approximate` the matrix serves a
  // chord iteration or a regular point's tangent only and may be approximate
  // (has_approximate_matrices()); F is exact either way.
  virtual bool matrix(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, Eigen::MatrixXd* A,
                      std::string* failure, bool approximate) = 0;
  // Whether matrix(..., approximate = true) may differ from the exact one: a corrector that fails
  // on it is then retried with the exact matrix.
  virtual bool has_approximate_matrices() const { return false; }
  // The matrix of matrix(..., approximate = true) alone, for a caller that has F at (x, lambda)
  // or does not need it; a system may save F's evaluation. The default: matrix's, F thrown away.
  virtual bool approximate_matrix(const Eigen::VectorXd& x, double lambda, Eigen::MatrixXd* A, std::string* failure) {
    Eigen::VectorXd F;
    return matrix(x, lambda, &F, A, failure, true);
  }
  // The start x0 corrected at fixed lambda. The default: Newton on F(., lambda) with F_x from
  // matrix(), to max |F| <= tolerance, at most 50 iterations, undamped (a system whose starts
  // need damping or a global search provides its own).
  virtual FixedParameterSolve solve_at(const Eigen::VectorXd& x0, double lambda, double tolerance);
  // The corrector's tolerance on max |F| when the options give none.
  virtual double default_corrector_tolerance() const { return 1e-10; }
};

}  // namespace kirchhoff
