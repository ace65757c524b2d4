#include "kirchhoff/continuation/rod_continuation.hpp"

#include <cmath>
#include <stdexcept>

#include "kirchhoff/analysis/point_record.hpp"

namespace kirchhoff {
namespace {

double sign_of(double v) { return v < 0 ? -1.0 : 1.0; }

// The rod options checked before anything is built from them (the engine checks its own again).
const RodContinuationOptions& validated(const RodContinuationOptions& options) {
  if (std::string e = options.validate(); !e.empty()) throw std::invalid_argument(e);
  return options;
}

}  // namespace

std::string RodRecordOptions::validate() const {
  // As a case file's [output] samples (case_file.hpp): 1e5 samples cost ~2 s per point already.
  if (samples < 2 || samples > 100000) return "samples must be in [2, 100000]";
  if (!(stability_field_tolerance >= 0 && stability_field_tolerance < 1e-3))
    return "stability_field_tolerance must be in [0, 1e-3) (0: the state's tolerance)";
  return {};
}

std::string RodContinuationOptions::validate() const {
  if (std::string e = ContinuationOptions::validate(); !e.empty()) return e;
  if (!(march_sensitivity_tol >= 0)) return "march_sensitivity_tol must be >= 0 (0: the problem's own)";
  return RodRecordOptions::validate();
}

RodContinuation::RodContinuation(const ShootingProblem& problem, const RodContinuationOptions& options)
    : Continuation(std::make_unique<ShootingSystem>(problem, validated(options).parameter,
                                                    options.march_sensitivity_tol),
                   options,
                   // The rod layer's recorder reads the derived list completed with the events'
                   // quantities.
                   [&options](const ContinuationOptions& configured) {
                     return rod_point_recorder(options, configured.derived);
                   }) {}

const ShootingProblem& RodContinuation::problem() const {
  return static_cast<const ShootingSystem&>(system()).problem();
}

long RodContinuation::rhs_evaluations() const {
  return static_cast<const ShootingSystem&>(system()).rhs_evaluations();
}

SymmetricBranchStart axial_symmetry_branch(RodContinuation& straight, const ContinuationPoint& bp, double sign) {
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

RodContinuationOptions bifurcating_branch_options(RodContinuationOptions options) {
  options.target = NAN;
  options.direction = 1.0;
  return options;
}

ContinuationResult follow_bifurcating_branch(RodContinuation& run, const ContinuationPoint& bp,
                                             RodContinuationOptions options, double side,
                                             const BranchSinkFactory& sink_for) {
  options = bifurcating_branch_options(std::move(options));
  if (bp.multiplicity == 2 && run.problem().definition().kind == RodKind::Spatial) {
    const SymmetricBranchStart start = axial_symmetry_branch(run, bp, side);
    const ShootingProblem switched(start.definition);
    RodContinuation next(switched, options);
    return next.run_along(start.x, start.parameter, start.direction, PointType::BranchPoint,
                          sink_for(switched, true));
  }
  ShootingProblem at_bp = run.problem();
  at_bp.set_parameter(options.parameter, bp.parameter);
  RodContinuation next(at_bp, options);
  return next.switch_branch(bp, sink_for(at_bp, false), side);
}

}  // namespace kirchhoff
