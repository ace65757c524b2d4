#include "kirchhoff/continuation/shooting_system.hpp"

#include <algorithm>
#include <stdexcept>

namespace kirchhoff {

ShootingSystem::ShootingSystem(const ShootingProblem& problem, std::string parameter, double march_sensitivity_tol)
    : problem_(problem), parameter_(std::move(parameter)) {
  if (!problem_.parameters().contains(parameter_))
    throw std::invalid_argument("continuation parameter '" + parameter_ + "' is not a parameter of the problem");
  const ProblemDefinition& d = problem_.definition();
  for (const auto& u : d.unknown_parameters)
    if (u == parameter_)
      throw std::invalid_argument("'" + parameter_ + "' is solved for (an unknown); continue in another parameter");
  const double own = std::max(d.options.integrator.sensitivity_tol, d.options.integrator.abs_tol);
  // (Not with obstacles or contacts: their events and energy differences follow Newton's last
  // iterates to better than the looser matrices' 1e-9, RodContinuationOptions::march_sensitivity_tol.)
  if (problem_.without_obstacles() && march_sensitivity_tol > own) {
    ProblemDefinition loose = d;
    loose.options.integrator.sensitivity_tol = march_sensitivity_tol;
    march_problem_.emplace(std::move(loose));
  }
}

double ShootingSystem::default_corrector_tolerance() const {
  return std::max(1e-10, problem_.definition().options.newton.residual_tolerance);
}

const ShootingProblem& ShootingSystem::problem_at(double lambda) {
  problem_.set_parameter(parameter_, lambda);
  return problem_;
}

template <class Evaluation>
bool ShootingSystem::at(ShootingProblem& p, double lambda, std::string* failure, Evaluation&& evaluation) {
  try {
    problem_.set_parameter(parameter_, lambda);
    if (&p != &problem_) p.set_parameter(parameter_, lambda);
    return evaluation();
  } catch (const std::invalid_argument& e) {
    if (failure) *failure = "no rod at " + parameter_ + " = " + std::to_string(lambda) + ": " + e.what();
    return false;
  }
}

bool ShootingSystem::residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, std::string* failure) {
  return at(problem_, lambda, failure, [&] { return problem_.evaluate(x, F, nullptr, failure); });
}

bool ShootingSystem::matrix(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, Eigen::MatrixXd* A,
                            std::string* failure, bool approximate) {
  if (approximate && march_problem_)
    return at(*march_problem_, lambda, failure,
              [&] { return problem_.evaluate(x, F, nullptr, failure) && march_matrix_of(x, A, failure); });
  return at(problem_, lambda, failure, [&] { return matrix_of(problem_, x, F, A, failure); });
}

bool ShootingSystem::approximate_matrix(const Eigen::VectorXd& x, double lambda, Eigen::MatrixXd* A,
                                        std::string* failure) {
  if (!march_problem_) return ParameterisedSystem::approximate_matrix(x, lambda, A, failure);
  return at(*march_problem_, lambda, failure, [&] { return march_matrix_of(x, A, failure); });
}

bool ShootingSystem::march_matrix_of(const Eigen::VectorXd& x, Eigen::MatrixXd* A, std::string* failure) {
  Eigen::VectorXd y_end;
  return march_problem_->matrix_at_sensitivity_tolerance(x, A, &y_end, failure) &&
         append_parameter_column(*march_problem_, x, y_end, A, failure);
}

bool ShootingSystem::matrix_of(ShootingProblem& p, const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* A,
                               std::string* failure) {
  Eigen::VectorXd y_end;
  return p.evaluate_with_end(x, F, A, &y_end, failure) && append_parameter_column(p, x, y_end, A, failure);
}

bool ShootingSystem::append_parameter_column(const ShootingProblem& p, const Eigen::VectorXd& x,
                                             const Eigen::VectorXd& y_end, Eigen::MatrixXd* A, std::string* failure) {
  Eigen::VectorXd F_lambda;
  if (!p.parameter_derivative(x, parameter_, &F_lambda, failure, &y_end)) return false;
  // A column appended in place: the matrices of long rods are tens of megabytes, and realloc
  // extends such blocks without copying them.
  const int n = problem_.size();
  A->conservativeResize(n, n + 1);
  A->col(n) = F_lambda;
  return true;
}

FixedParameterSolve ShootingSystem::solve_at(const Eigen::VectorXd& x0, double lambda, double tolerance) {
  problem_.set_parameter(parameter_, lambda);
  const ShootingResult r = solve(problem_, x0);
  FixedParameterSolve out;
  out.x = r.x;
  // The continuation works to its own corrector tolerance: a start that stalls below it (a case
  // asking Newton for 1e-12 at large loads, say) is good enough.
  out.converged = r.summary.converged() || r.summary.residual_norm <= tolerance;
  out.residual_norm = r.summary.residual_norm;
  out.report = r.summary.brief_report();
  return out;
}

const ShootingProblem& shooting_problem_at(ParameterisedSystem& system, double lambda) {
  auto* shooting = dynamic_cast<ShootingSystem*>(&system);
  if (!shooting) throw std::logic_error("this continuation follows a system that is not a rod's shooting problem");
  return shooting->problem_at(lambda);
}

}  // namespace kirchhoff
