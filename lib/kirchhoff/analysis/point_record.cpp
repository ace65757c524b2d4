#include "kirchhoff/analysis/point_record.hpp"

#include <algorithm>
#include <any>

#include "kirchhoff/analysis/detail/derived_quantities.hpp"
#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/continuation/shooting_system.hpp"

namespace kirchhoff {
namespace {

// H is flagged as not flat above this fraction of its scale (the standard).
constexpr double kFlatH = 1e-9;

const RodPointInvariants& kept(const PointRecord& point) {
  static const RodPointInvariants none;
  const auto* rod = std::any_cast<RodPointInvariants>(&point.extra);
  return rod ? *rod : none;
}

}  // namespace

const InvariantReport& invariants_of(const PointRecord& point) { return kept(point).invariants; }

bool H_is_flat(const PointRecord& point) { return kept(point).H_flat; }

PointRecorder rod_point_recorder(const RodRecordOptions& options, const std::vector<std::string>& derived) {
  PointRecorder recorder;
  // Where nothing recorded reads beyond s = 0, the rod is not integrated again to describe a
  // point (13 % of the instructions of the Euler column's branch recording theta0 alone); a
  // field's domain is checked along the whole profile (make_solution), so not with a field.
  const bool start_only = !options.compute_invariants && derived_read_start_only(derived);
  const bool described = options.compute_invariants || !derived.empty();
  // Every corrected point is checked to be an equilibrium: with the axial phase condition, a
  // point of the unfolded system with mu != 0 is not one (from the straight twisted rod the march
  // went along mu at a fixed twist, every row "stable"); the step is refused, as a corrector that
  // failed (ContinuationPoint::check_failure).
  recorder.describe = [samples = options.samples, derived, start_only, described](ParameterisedSystem& system,
                                                                               ContinuationPoint* point) {
    ContinuationPoint& p = *point;
    const ShootingProblem& problem = shooting_problem_at(system, p.parameter);
    const Parameters at = problem.parameters_at(p.x);
    if (std::string why = unfolding_failure(at); !why.empty()) {
      p.check_failure = why;
      return;
    }
    if (!described) return;
    ShootingResult r;
    r.x = p.x;
    r.summary.status = SolverStatus::Converged;
    r.parameters = at;
    const bool at_start = start_only && !problem.equations(at)->model().field;
    const Solution s = at_start ? make_start_solution(problem, std::move(r), derived)
                                : make_solution(problem, std::move(r), samples, derived);
    if (!s.result.summary.converged()) p.check_failure = s.result.summary.message;
    p.derived = s.derived;
    // Parameters solved for belong on the branch too (e.g. the load of a displacement-controlled run).
    for (const auto& name : problem.definition().unknown_parameters) p.derived[name] = at.get(name);
    const InvariantStats& H = s.invariants.H;
    p.extra = RodPointInvariants{s.invariants, !H.applies || H.spread <= kFlatH * std::max(1.0, H.scale)};
  };
  if (options.compute_stability)
    recorder.record = [field_tolerance = options.stability_field_tolerance](ParameterisedSystem& system,
                                                                              ContinuationPoint* point) {
      // Not the extended contacts' discretised energy (seconds per point: a flat leg has thousands).
      StabilityOptions stability_options;
      stability_options.extended_contacts = false;
      stability_options.field_tolerance = field_tolerance;
      // Where the conjugate points leave the index undefined, the discretised energy's, as solve
      // reports it (a column on a stiff foundation: 33 of 240 points of its straight branch).
      const ShootingProblem& problem = shooting_problem_at(system, point->parameter);
      const StabilityReport stability = with_discretised_index_where_undefined(
          analyse_stability(problem, point->x, stability_options), problem, point->x, false);
      point->stability_index = stability.index;
      point->zero_modes = stability.zero_modes;
      point->stability_reason = stability.index ? "" : stability.reason;
    };
  return recorder;
}

}  // namespace kirchhoff
