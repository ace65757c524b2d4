#include "kirchhoff/continuation/rod_continuation.hpp"

#include <cmath>
#include <stdexcept>

#include "kirchhoff/analysis/point_record.hpp"

namespace kirchhoff {
namespace {

double sign_of(double v) { return v < 0 ? -1.0 : 1.0; }

}  // namespace

Continuation::Continuation(const ShootingProblem& problem, ContinuationOptions options) : options_(std::move(options)) {
  if (std::string e = options_.validate(); !e.empty()) throw std::invalid_argument(e);
  system_ = std::make_unique<ShootingSystem>(problem, options_.parameter, options_.march_sensitivity_tol);
  configure();
  // What a rod's point records comes from the recorder, by default the rod layer's (it reads the
  // derived list completed with the events' quantities in configure()).
  if (!options_.recorder) options_.recorder = rod_point_recorder(options_);
}

const ShootingProblem& Continuation::problem() const {
  const auto* shooting = dynamic_cast<const ShootingSystem*>(system_.get());
  if (!shooting) throw std::logic_error("this continuation follows a system that is not a rod's shooting problem");
  return shooting->problem();
}

SymmetricBranchStart axial_symmetry_branch(Continuation& straight, const ContinuationPoint& bp, double sign) {
  const ShootingProblem& problem = straight.problem();
  const Eigen::MatrixXd N = straight.bifurcation_directions(bp, 2);
  // The phase condition m(0).e2 = 0, linearised: a row on the unknowns at s = 0.
  const auto eq = problem.equations(problem.parameters());
  const Eigen::RowVectorXd phase = eq->slot_map(Slot::Moment).row(1);
  const int n_state = problem.state_size();
  auto phase_of = [&](const Eigen::VectorXd& v) { return phase.dot(v.head(n_state)); };
  Eigen::VectorXd d = N.col(0) * phase_of(N.col(1)) - N.col(1) * phase_of(N.col(0));
  if (d.norm() < 1e-12) d = std::abs(phase_of(N.col(0))) < std::abs(phase_of(N.col(1))) ? N.col(0) : N.col(1);
  d.normalize();
  for (int i = 0; i < d.size(); ++i)
    if (std::abs(d[i]) > 1e-8) {
      d *= sign_of(d[i]) * sign_of(sign);
      break;
    }
  SymmetricBranchStart start;
  start.definition = problem.definition();
  add_axial_phase_condition(start.definition);
  const int n = problem.size();
  // The unfolding parameter is the last unknown of the new problem; it starts at 0.
  start.x = Eigen::VectorXd::Zero(n + 1);
  start.x.head(n) = bp.x;
  start.parameter = bp.parameter;
  start.direction = Eigen::VectorXd::Zero(n + 2);
  start.direction.head(n) = d.head(n);
  start.direction[n + 1] = d[n];
  return start;
}

ContinuationOptions bifurcating_branch_options(ContinuationOptions options) {
  options.target = NAN;
  options.direction = 1.0;
  return options;
}

ContinuationResult follow_bifurcating_branch(Continuation& run, const ContinuationPoint& bp,
                                             ContinuationOptions options, double side,
                                             const BranchSinkFactory& sink_for) {
  options = bifurcating_branch_options(std::move(options));
  if (bp.multiplicity == 2 && run.problem().definition().kind == RodKind::Spatial) {
    const SymmetricBranchStart start = axial_symmetry_branch(run, bp, side);
    const ShootingProblem switched(start.definition);
    Continuation next(switched, options);
    return next.run_along(start.x, start.parameter, start.direction, PointType::BranchPoint,
                          sink_for(switched, true));
  }
  ShootingProblem at_bp = run.problem();
  at_bp.set_parameter(options.parameter, bp.parameter);
  Continuation next(at_bp, options);
  return next.switch_branch(bp, sink_for(at_bp, false), side);
}

}  // namespace kirchhoff
