#include "kirchhoff/jobs/homotopy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/contact/self_passage.hpp"
#include "kirchhoff/continuation/continuation.hpp"

namespace kirchhoff {
namespace {

// A name for t that no parameter of the case has.
std::string fresh_name(const Parameters& p) {
  std::string name = "homotopy";
  for (int k = 1; p.contains(name); ++k) name = "homotopy_" + std::to_string(k);
  return name;
}

void check_changes(const ProblemDefinition& d, const std::vector<ParameterChange>& changes) {
  for (const auto& c : changes) {
    if (!d.parameters.contains(c.name)) throw std::invalid_argument("no parameter '" + c.name + "'");
    for (const auto& unknown : d.unknown_parameters)
      if (unknown == c.name)
        throw std::invalid_argument("parameter '" + c.name + "' is solved for: its value is a guess, not a change");
    if (find_dependent(d.dependent_parameters, c.name))
      throw std::invalid_argument("parameter '" + c.name + "' is computed from other parameters");
  }
}

// The start definition with t as a new parameter (0) and each changed parameter computed from it.
// Its rules come first: a case's own dependent parameters are then computed from the moving values.
ProblemDefinition homotopy_definition(ProblemDefinition d, const std::vector<ParameterChange>& changes,
                                      const std::string& t) {
  std::vector<DependentParameter> rules;
  for (const auto& change : changes)
    rules.push_back({change.name, [change, t](const Parameters& p) { return change.at(p.get(t)); }, {t}});
  rules.insert(rules.end(), d.dependent_parameters.begin(), d.dependent_parameters.end());
  d.dependent_parameters = std::move(rules);
  d.parameters.set(t, 0.0);
  return d;
}

RodContinuationOptions path_options(const ShootingProblem& problem, const std::string& t, const Eigen::VectorXd& x_start,
                                 const HomotopyOptions& options) {
  RodContinuationOptions o;
  o.parameter = t;
  // The arclength measures (dx, dt) together, and t spans only [0, 1] while the unknowns move by
  // amounts of their own size: longer steps where they are large (plectoneme.toml to its fold
  // at 1.77 turns: 120 s -> 27 s). Only by the square root of that size: steps in proportion
  // to it located the supports' meeting on Fig. 3's branch 1e-2 off (its correctors fail
  // on long steps near the branch point), at the square root to 1e-5 as with unit steps.
  const double scale = std::sqrt(1.0 + x_start.norm());
  o.initial_step *= scale;
  o.max_step *= scale;
  // Values far above the file's (EI = 1e4, P = 3e4 from 1 and 12) carry the unknowns over orders
  // of magnitude: the steps grow with them (in proportion to |x| beyond its size at the start), as
  // the corrector's convergence allows. Not with obstacles: their paths change contact sets
  // along the way, and longer steps there reached other equilibria (the indenter at rise 0.3663
  // ended where Newton could not polish it; the cavity reached an equilibrium of index 2).
  if (problem.without_obstacles()) o.max_step_reference_size = std::max(1.0, x_start.norm());
  o.target = 1.0;
  o.max_points = options.max_points;
  o.deadline = options.deadline;
  o.stop_at_fold = !options.through_folds;
  o.compute_invariants = false;
  const bool large = problem.size() > options.branch_point_unknown_limit;
  o.detect_branch_points = !large;
  if (large) {
    // Long multiple-shooting rods: a point's Jacobian costs tens of residuals, so the steps are
    // long and the corrector's iterations cheap (as the plectoneme sweeps follow their branches).
    o.modified_newton = true;
    o.reuse_jacobian_iterations = 2;
    o.corrector_max_iterations = 16;
    o.grow_iterations = 10;
    o.shrink_iterations = 14;
  }
  // A rod with self-contact must not pass through itself between two steps.
  guard_self_passage(problem, &o);
  return o;
}

std::string stop_word(StopReason reason) {
  switch (reason) {
    case StopReason::ReachedTarget: return "reached";
    case StopReason::FoldStop: return "fold";
    case StopReason::StepTooSmall: return "step_too_small";
    case StopReason::MaxPoints: return "max_points";
    case StopReason::TimeLimit: return "time_limit";
    case StopReason::Inadmissible: return "inadmissible";
    case StopReason::StartFailed: return "start_failed";
    default: return to_string(reason);
  }
}

// A fold located within this of the path's start (in t) is the start itself.
constexpr double kAtTheStart = 1e-8;

// Why the path ended short of t = 1, for the user.
std::string stop_message(const HomotopyResult& h, const std::vector<ParameterChange>& changes,
                         const std::string& detail) {
  std::ostringstream m;
  m.precision(10);
  if (h.stop == "fold" && std::abs(h.fraction) < kAtTheStart) {
    // A "fold" where the path starts: the case's own solution is singular, most often one of a
    // continuous family (a naturally curved ring pinned at one point turns about its pin: the
    // homotopy in its curvature stopped at fraction -1.6e-13, a probe's).
    m << "the homotopy cannot leave the case's solution at its file's values (a fold at homotopy fraction "
      << h.fraction << "): its Jacobian is singular there, as at a fold or on a continuous family of equilibria "
      << "(a symmetry the case leaves free, e.g. a ring that can turn about its pin); fix the symmetry in the case "
         "or solve directly";
  } else if (h.stop == "fold") {
    // The detail only repeats the fold's place in t.
    m << "the branch the case's solution lies on turns back at a fold at " << describe_values(changes, h.fraction)
      << " (homotopy fraction " << h.fraction << ") before reaching the requested values";
  } else {
    m << "the homotopy stopped (" << h.stop << ") at " << describe_values(changes, h.fraction)
      << " (homotopy fraction " << h.fraction << ")";
    if (!detail.empty()) m << ": " << detail;
  }
  return m.str();
}

// Newton at exactly b from the path's end (t = 1 to the continuation's tolerance).
void polish(const ProblemDefinition& start, const std::vector<ParameterChange>& changes,
            const std::vector<PointContact>& contacts, const Eigen::VectorXd& x, HomotopyResult* h) {
  ProblemDefinition d = start;
  for (const auto& c : changes) d.parameters.set(c.name, c.to);
  d.contacts = contacts;
  const ShootingProblem problem(d);
  // As the active-set loop solves (a flat contact's stall at round-off is converged), so that a
  // solve by homotopy accepts what a direct one does.
  std::string round_off;
  h->result = solve_on_active_set(problem, x, &round_off);
  if (!round_off.empty()) h->contact_changes.push_back("at the requested values: " + round_off);
  h->definition = std::move(d);
  h->reached = h->result.summary.converged();
  if (!h->reached) {
    h->stop = "not_converged";
    h->message = "the path reached the requested values but Newton there did not converge: " +
                 h->result.summary.brief_report();
  }
}

// A contact change is reported at "t = value: what": at the parameters' values instead.
std::string in_parameter_values(const std::string& line, const std::string& t,
                                const std::vector<ParameterChange>& changes) {
  const std::string prefix = t + " = ";
  const size_t colon = line.find(": ");
  if (line.rfind(prefix, 0) != 0 || colon == std::string::npos) return line;
  const double at = std::strtod(line.c_str() + prefix.size(), nullptr);
  return describe_values(changes, at) + line.substr(colon);
}

}  // namespace

std::string describe_values(const std::vector<ParameterChange>& changes, double t) {
  std::ostringstream out;
  out.precision(10);
  for (size_t k = 0; k < changes.size(); ++k) out << (k ? ", " : "") << changes[k].name << " = " << changes[k].at(t);
  return out.str();
}

HomotopyResult follow_homotopy(const ProblemDefinition& start, const Eigen::VectorXd& x_start,
                               const std::vector<ParameterChange>& changes, const HomotopyOptions& options) {
  check_changes(start, changes);
  const std::string t = fresh_name(start.parameters);
  const ProblemDefinition path = homotopy_definition(start, changes, t);
  const ShootingProblem problem(path);
  const RodContinuationOptions o = path_options(problem, t, x_start, options);
  HomotopyResult h;
  h.branch_points_checked = o.detect_branch_points;
  ContinuationResult run;
  std::vector<PointContact> contacts = start.contacts;
  if (start.obstacles.empty() && !start.moving_obstacles) {
    RodContinuation continuation(problem, o);
    run = continuation.run(x_start);
    h.residual_evaluations = continuation.evaluations().residuals;
    h.jacobian_evaluations = continuation.evaluations().matrices;
  } else {
    ContactContinuationResult legs = continue_with_contacts_from(path, x_start, o);
    run = std::move(legs.result);
    for (const auto& line : legs.changes) h.contact_changes.push_back(in_parameter_values(line, t, changes));
    contacts = legs.definition.contacts;
  }
  h.points = static_cast<int>(run.points.size());
  for (const auto& p : run.points)
    if (p.type == PointType::BranchPoint) h.branch_points.push_back(p.parameter);
  h.stop = stop_word(run.reason);
  if (run.points.empty()) {
    h.message = "the homotopy could not start: " + run.message;
    return h;
  }
  h.fraction = run.points.back().parameter;
  if (run.reason != StopReason::ReachedTarget) {
    // A corrector that failed down to the minimum step on one segment has most often met the
    // residual's floor of an ill-conditioned shooting (the Euler column's first mode at P = 454:
    // best residual 1.5e-10 against the tolerance 1e-10; with 8 segments P = 500 converges).
    std::string why = run.message;
    if (run.reason == StopReason::StepTooSmall) {
      if (problem.segments() == 1) why += "; " + single_segment_hint();
      if (const std::string units = scale_hint(problem, run.points.back().x); !units.empty()) why += "; " + units;
    }
    h.message = stop_message(h, changes, why);
    return h;
  }
  polish(start, changes, contacts, run.points.back().x, &h);
  if (h.reached) h.fraction = 1.0;
  return h;
}

}  // namespace kirchhoff
