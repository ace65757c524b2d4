#include "kirchhoff/continuation/deflation.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace kirchhoff {

DeflationOperator::DeflationOperator(Eigen::VectorXd scale, double power, double shift)
    : scale_(std::move(scale)), power_(power), shift_(shift) {
  if (!(scale_.array() > 0).all() || !scale_.allFinite())
    throw std::invalid_argument("deflation: every unknown's scale must be positive and finite");
  if (!(power_ > 0) || !(shift_ >= 0)) throw std::invalid_argument("deflation: needs p > 0 and sigma >= 0");
}

void DeflationOperator::add_root(const Eigen::VectorXd& root) {
  if (root.size() != scale_.size()) throw std::invalid_argument("deflation: a root of the wrong size");
  roots_.push_back(root);
}

double DeflationOperator::distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const {
  return ((a - b).array() / scale_.array()).matrix().norm();
}

double DeflationOperator::nearest_root_distance(const Eigen::VectorXd& x) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& r : roots_) best = std::min(best, distance(x, r));
  return best;
}

double DeflationOperator::value(const Eigen::VectorXd& x) const {
  double M = 1.0;
  for (const auto& r : roots_) M *= std::pow(distance(x, r), -power_) + shift_;
  return M;
}

Eigen::VectorXd DeflationOperator::log_gradient(const Eigen::VectorXd& x) const {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  const Eigen::ArrayXd inverse_square = scale_.array().square().inverse();
  for (const auto& r : roots_) {
    const double d = distance(x, r);
    // m = d^-p + sigma; grad d = S^2 (x - r) / d, so grad m = -p d^(-p-2) S^2 (x - r).
    const double m = std::pow(d, -power_) + shift_;
    const Eigen::VectorXd grad_m = -power_ * std::pow(d, -power_ - 2.0) * ((x - r).array() * inverse_square).matrix();
    v += grad_m / m;
  }
  return v;
}

namespace {

struct Evaluation {
  bool ok = false;
  Eigen::VectorXd F;
  double norm = std::numeric_limits<double>::infinity();  // max |F_i|
};

Evaluation evaluate_residual(const NonlinearSystem& system, const Eigen::VectorXd& x) {
  Evaluation e;
  std::string failure;
  e.ok = system.evaluate(x, &e.F, nullptr, &failure);
  if (e.ok) e.norm = max_abs_or_nan(e.F);
  e.ok = e.ok && std::isfinite(e.norm);
  return e;
}

bool past(const std::chrono::steady_clock::time_point& deadline) { return std::chrono::steady_clock::now() > deadline; }

NewtonSummary stop(NewtonSummary s, SolverStatus status, const std::string& message) {
  s.status = status;
  s.message = message;
  return s;
}

}  // namespace

NewtonSummary deflated_newton(const NonlinearSystem& system, Eigen::VectorXd& x, const DeflationOperator& deflation,
                              const DeflatedNewtonOptions& options) {
  NewtonSummary summary;
  const Eigen::ArrayXd& scale = deflation.scale().array();
  for (int it = 0; it <= options.max_iterations; ++it) {
    if (past(options.deadline)) return stop(summary, SolverStatus::TimeLimit, "wall-clock limit");
    Eigen::VectorXd F;
    Eigen::MatrixXd J;
    std::string failure;
    ++summary.evaluations;
    if (!system.evaluate(x, &F, &J, &failure)) return stop(summary, SolverStatus::IntegrationFailed, failure);
    summary.residual_norm = max_abs_or_nan(F);
    if (!std::isfinite(summary.residual_norm) || !J.allFinite())
      return stop(summary, SolverStatus::NotFinite, "the residual or its Jacobian is not finite");
    summary.iterations = it;
    summary.history.push_back(summary.residual_norm);
    const auto at_root = [&](const char* how) {
      if (deflation.nearest_root_distance(x) <= options.known_root_distance)
        return stop(summary, SolverStatus::MaxIterations, "returned to a known root despite the deflation");
      return stop(summary, SolverStatus::Converged, how);
    };
    if (summary.residual_norm <= options.residual_tolerance) return at_root("converged");
    if (it == options.max_iterations) break;
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(J);
    if (!(lu.rcond() > 1e-15)) return stop(summary, SolverStatus::SingularJacobian, "singular Jacobian");
    const Eigen::VectorXd d = lu.solve(-F);
    if (step_at_round_off(d.lpNorm<Eigen::Infinity>(), x.lpNorm<Eigen::Infinity>(), summary.residual_norm,
                          options.step_tolerance, options.residual_tolerance))
      return at_root("step at round-off");
    // The deflated step delta = d / (1 - v.d) (Sherman-Morrison on J_G, see the header).
    const double denominator = 1.0 - deflation.log_gradient(x).dot(d);
    if (!(std::abs(denominator) > options.min_denominator))
      return stop(summary, SolverStatus::SingularJacobian, "the deflated Jacobian is singular here");
    Eigen::VectorXd delta = d / denominator;
    const double scaled = (delta.array() / scale).abs().maxCoeff();
    if (scaled > options.max_scaled_step) delta *= options.max_scaled_step / scaled;
    // Backtracking on ||G|| = M ||F||_2; when no shorter step lowers it, the full step is taken
    // anyway: a deflated iterate often has to climb out of a known root's basin first.
    const double merit = deflation.value(x) * F.norm();
    double lambda = 1.0;
    Eigen::VectorXd accepted;
    for (int b = 0; b <= options.max_backtracks; ++b, lambda *= 0.5) {
      const Eigen::VectorXd trial = x + lambda * delta;
      const Evaluation e = evaluate_residual(system, trial);
      ++summary.evaluations;
      if (!e.ok) continue;  // the integration failed there: shorter
      if (accepted.size() == 0) accepted = trial;  // the longest step that can be integrated
      if (deflation.value(trial) * e.F.norm() < merit) {
        accepted = trial;
        break;
      }
    }
    if (accepted.size() == 0)
      return stop(summary, SolverStatus::LineSearchFailed, "no step along the deflated direction could be integrated");
    x = accepted;
  }
  std::ostringstream message;
  message << "no convergence in " << options.max_iterations << " deflated iterations";
  return stop(summary, SolverStatus::MaxIterations, message.str());
}

}  // namespace kirchhoff
