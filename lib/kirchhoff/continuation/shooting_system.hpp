// A rod's shooting problem as the continuation engine follows it: F(x, lambda) with lambda one of
// the problem's parameters, [F_x F_lambda] from the variational equations and
// ShootingProblem::parameter_derivative. The march's own matrices (approximate = true) come from
// a copy of the problem whose variational equations are held to march_sensitivity_tol
// (RodContinuationOptions) where that applies: not for problems with obstacles or contacts, nor where
// the problem's own tolerance is already that loose.
#pragma once

#include <optional>
#include <string>

#include "kirchhoff/continuation/parameterised_system.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

class ShootingSystem final : public ParameterisedSystem {
 public:
  // The problem is copied; its value of `parameter` is the starting one. Throws
  // std::invalid_argument when `parameter` is not a parameter of the problem, or is solved for.
  ShootingSystem(const ShootingProblem& problem, std::string parameter, double march_sensitivity_tol);

  int size() const override { return problem_.size(); }
  double parameter() const override { return problem_.parameters().get(parameter_); }
  // A parameter value where no rod can be built (a self-contact radius below zero, reached by a
  // corrector iterate far off the branch) is a failed evaluation ("no rod at ..."), not an
  // exception: the engine shortens the step as for any other failure.
  bool residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, std::string* failure) override;
  bool matrix(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, Eigen::MatrixXd* A, std::string* failure,
              bool approximate) override;
  // The march's matrix (approximate, with the twin) is the same function of (x, lambda) whether
  // or not F comes with it: the twin integrates the state with the variational equations in one
  // pass at its tolerance (ShootingProblem::matrix_at_sensitivity_tolerance), the end conditions'
  // rows and F_lambda read that pass's end state, and F, where asked, is problem_'s own residual.
  // So a resumed run's restored matrices are the uninterrupted run's, however they were reached.
  bool approximate_matrix(const Eigen::VectorXd& x, double lambda, Eigen::MatrixXd* A, std::string* failure) override;
  bool has_approximate_matrices() const override { return march_problem_.has_value(); }
  // The shooting solve (damped Newton, its fallback search, its checks) at fixed lambda.
  FixedParameterSolve solve_at(const Eigen::VectorXd& x0, double lambda, double tolerance) override;
  // 1e-10, or the problem's Newton residual tolerance (a case's [solver] tolerance) when that is
  // looser: rods with large forces need it.
  double default_corrector_tolerance() const override;

  const ShootingProblem& problem() const { return problem_; }
  // Right-hand sides integrated by the problem and its looser twin together.
  long rhs_evaluations() const {
    return problem_.rhs_evaluations() + (march_problem_ ? march_problem_->rhs_evaluations() : 0);
  }
  // The problem with the continued parameter at lambda: what a recorder describes a point on.
  const ShootingProblem& problem_at(double lambda);

 private:
  bool matrix_of(ShootingProblem& p, const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* A,
                 std::string* failure);
  // The twin's matrix alone (approximate_matrix), lambda set.
  bool march_matrix_of(const Eigen::VectorXd& x, Eigen::MatrixXd* A, std::string* failure);
  // F_lambda appended to A = F_x in place, from the problem p and its end state y_end.
  bool append_parameter_column(const ShootingProblem& p, const Eigen::VectorXd& x, const Eigen::VectorXd& y_end,
                               Eigen::MatrixXd* A, std::string* failure);
  // Runs `evaluation` of p (problem_ or its twin) at lambda, an invalid parameter value turned
  // into a failure.
  template <class Evaluation>
  bool at(ShootingProblem& p, double lambda, std::string* failure, Evaluation&& evaluation);

  ShootingProblem problem_;
  std::optional<ShootingProblem> march_problem_;
  std::string parameter_;
};

// The shooting problem of a system that is a ShootingSystem, with its continued parameter at
// lambda (what a rod's PointRecorder describes); throws std::logic_error for another system.
const ShootingProblem& shooting_problem_at(ParameterisedSystem& system, double lambda);

}  // namespace kirchhoff
