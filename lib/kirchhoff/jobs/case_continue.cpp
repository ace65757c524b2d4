#include "kirchhoff/jobs/case_continue.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>

#include "kirchhoff/analysis/discrete_seed.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/contact/self_passage.hpp"
#include "kirchhoff/equations/integrator.hpp"
#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/deflated_continuation.hpp"

namespace kirchhoff {

bool ended_normally(StopReason reason) {
  return reason != StopReason::StartFailed && reason != StopReason::StepTooSmall &&
         reason != StopReason::Inadmissible && reason != StopReason::TimeLimit;
}

const char kDeflateRefusal[] =
    "--deflate starts every branch from the equilibria it finds: it does not combine with --resume, --start-from, "
    "--switch-at-bp or --seed (a --deflate run is not resumable)";

namespace {


std::string text(double value) {
  std::ostringstream o;
  o << value;  // six significant digits, as the progress lines
  return o.str();
}

// The continuation options of a request: the event quantities among the derived ones (the
// columns every point has).
RodContinuationOptions options_for(const Case& c, const ContinueRequest& r) {
  RodContinuationOptions o;
  o.parameter = r.parameter;
  o.target = r.target.value_or(std::numeric_limits<double>::quiet_NaN());
  o.direction = r.direction;
  o.initial_step = r.initial_step;
  o.min_step = r.min_step;
  o.max_step = r.max_step;
  o.max_points = r.max_points;
  o.samples = r.samples;
  o.detect_branch_points = r.detect_branch_points;
  o.compute_stability = r.compute_stability;
  o.derived = c.derived;
  o.events = r.events;
  for (const auto& e : o.events)
    if (std::find(o.derived.begin(), o.derived.end(), e.quantity) == o.derived.end()) o.derived.push_back(e.quantity);
  return o;
}

// The problem a branch belongs to: the case's, with the axial phase condition for "axial" (a
// case whose problem has the unfolding parameter has it already).
ProblemDefinition definition_for(const Case& c, const std::string& phase) {
  ProblemDefinition d = c.definition;
  if (phase == "axial" && !d.parameters.contains(kUnfoldingParameter)) add_axial_phase_condition(d);
  return d;
}

// Where the first point cannot be corrected from the case's guess at the --set values (the wall at
// Delta = 0.04: the active-set loop from the arch's guess does not settle), the equilibrium
// `solve` reports there, reached by homotopy from the file's values (case_solve.hpp), is where
// the branch starts instead: its unknowns and active set. Nothing where no homotopy applies (a
// start from another run or a seed, a resume, a phase condition, no --set of a parameter that is
// not solved for) or where it stops short too; either way `note` says what happened.
struct HomotopyStart {
  Eigen::VectorXd x;
  std::vector<PointContact> contacts;
};
std::optional<HomotopyStart> start_by_homotopy(const Case& c, const ContinueRequest& request,
                                               const std::string& direct_failure,
                                               const std::function<void(const std::string&)>& note) {
  if (request.start || request.resume || request.seed.ipopt || request.deflate) return std::nullopt;
  if (!request.phase_condition.empty() && request.phase_condition != "none") return std::nullopt;
  const std::vector<ParameterChange> changes = homotopy_changes(c);
  if (changes.empty()) return std::nullopt;
  CaseSolveOptions options;
  options.solution = options.stability = options.stability_check = false;
  const CaseSolve solved = solve_case(c, options);
  const std::string failed =
      "start: the first point could not be corrected from the case's guess (" + direct_failure + ")";
  if (!solved.converged() || !solved.solved.problem) {
    std::string why = solved.message.empty() ? solved.summary().brief_report() : solved.message;
    if (const size_t hint = why.find(kDirectSolveHint); hint != std::string::npos) why.erase(hint);
    note(failed + ", nor did solve's homotopy from the file's values reach them: " + why);
    return std::nullopt;
  }
  std::ostringstream line;
  line.precision(10);
  line << failed << "; the branch starts from the equilibrium solve reaches, by homotopy from the file's values (";
  for (size_t i = 0; i < changes.size(); ++i)
    line << (i ? ", " : "") << changes[i].name << " = " << changes[i].from << " -> " << changes[i].to;
  line << ")";
  note(line.str());
  return HomotopyStart{solved.solved.result.x, solved.solved.problem->definition().contacts};
}

// A run in progress: its state, its sinks, and the points it reports.
class Run {
 public:
  Run(const Case& c, const ContinueRequest& r, RodContinuationOptions options, const std::vector<ContinueSink*>& sinks)
      : c_(c), r_(r), options_(std::move(options)), sinks_(sinks) {}

  RunState state;

  void note(const std::string& line) {
    for (auto* s : sinks_) s->note(line);
  }
  void emit_state(bool resumable_point) {
    for (auto* s : sinks_) s->state(state, resumable_point);
  }
  void finish(bool resumable_run) {
    for (auto* s : sinks_) s->finish(resumable_run ? &state : nullptr);
  }
  // Reports the point as the next row, and records it as the row a run started from this one
  // starts at (a point the march cannot resume from is given in the state now; a resumable one
  // right after, with the march's state).
  void report(const ContinuationPoint& p, int branch, const std::string& phase,
              const std::vector<PointContact>* contacts, const ShootingProblem* problem) {
    ++state.row;
    RunPoint rp;
    rp.row = state.row;
    rp.branch = branch;
    rp.point = &p;
    rp.phase_condition = &phase;
    rp.contacts = contacts;
    rp.problem = problem;
    for (auto* s : sinks_) s->point(rp);
    note_undefined_index(p);
    state.written = WrittenPoint{state.row, branch, phase, p, contacts ? *contacts : std::vector<PointContact>{}};
    state.written->point.jacobian.reset();
    if (!resumable(p) && state.has_march) emit_state(false);
  }

  // The first row whose index is undefined, with why (the CSV leaves the cell empty and has no
  // column for the reason); the rest are not noted one by one.
  void note_undefined_index(const ContinuationPoint& p) {
    if (noted_undefined_index_ || p.stability_reason.empty()) return;
    noted_undefined_index_ = true;
    std::ostringstream line;
    line << "row " << state.row << " (" << r_.parameter << " = " << p.parameter
         << "): stability index undefined: " << p.stability_reason
         << " (later rows without an index are not noted one by one)";
    note(line.str());
  }

  ContinueRunResult deflated();
  ContinueRunResult plain(const Eigen::VectorXd& start_point, bool resuming);
  ContinueRunResult with_contacts(const Eigen::VectorXd& start_point, bool resuming);

 private:
  const Case& c_;
  const ContinueRequest& r_;
  RodContinuationOptions options_;
  const std::vector<ContinueSink*>& sinks_;
  const std::vector<PointContact> no_contacts_;
  bool noted_undefined_index_ = false;
};

// Every branch through the equilibria at the start, branch k from the k-th by energy (no state:
// not resumable).
ContinueRunResult Run::deflated() {
  EquilibriaOptions search;
  search.max_equilibria = r_.deflate_max;
  search.max_seconds = r_.max_seconds;
  const std::string phase = state.phase_condition;
  const auto sink_for = [&](int rank, const Equilibrium& start) -> PointSink {
    std::ostringstream line;
    line << "branch " << rank << ": from the equilibrium of energy " << start.energy << " ("
         << describe(start.stability) << ", found by " << start.found_by << ")";
    note(line.str());
    // (No active set and no problem: a deflated branch's legs are not told apart, so no profiles.)
    return [this, rank, &phase](const ContinuationPoint& p) { report(p, rank, phase, nullptr, nullptr); };
  };
  const EveryBranch all =
      continue_every_branch(c_.definition, c_.start_guess, c_.derived, c_.samples, options_, search, sink_for);
  ContinueRunResult out;
  out.equilibria = static_cast<int>(all.search.equilibria.size());
  out.search_stopped_because = all.search.stopped_because;
  std::ostringstream message;
  message << out.equilibria << " equilibria at the start (" << out.search_stopped_because << ")";
  out.ok = !all.branches.empty();
  const BranchFromEquilibrium* first_abnormal = nullptr;
  for (const auto& b : all.branches) {
    out.branches.push_back({b.rank, b.result.reason, b.result.message, b.contact_changes});
    message << "; branch " << b.rank << ": " << to_string(b.result.reason);
    if (!ended_normally(b.result.reason) && !first_abnormal) first_abnormal = &b;
    out.ok = out.ok && ended_normally(b.result.reason);
    out.last_branch = b.rank;
  }
  // The run's reason: the first branch that did not end normally, else the first branch's.
  if (all.branches.empty()) {
    out.status = "no_equilibrium";
    out.reason = StopReason::StartFailed;
  } else {
    out.reason = (first_abnormal ? *first_abnormal : all.branches.front()).result.reason;
    out.status = to_string(out.reason);
  }
  out.message = message.str();
  out.points = state.row + 1;
  finish(false);
  return out;
}

// The result of the last march of a run.
ContinueRunResult stopped(const ContinuationResult& result, int points, int branch) {
  ContinueRunResult out;
  out.reason = result.reason;
  out.status = to_string(result.reason);
  out.message = result.message;
  out.ok = ended_normally(result.reason);
  out.points = points;
  out.last_branch = branch;
  out.refused_steps = result.refused_steps;
  return out;
}

// The run asked for the K-th branch point and stopped before it.
ContinueRunResult no_branch_point(const ContinuationResult& result, int points, int k) {
  ContinueRunResult out = stopped(result, points, 0);
  out.ok = false;
  out.switch_requested = true;
  out.message = "no branch point " + std::to_string(k) + " before the run stopped (" + to_string(result.reason) +
                (result.message.empty() ? "" : ": " + result.message) + ")";
  return out;
}

// A start that cannot be integrated, or is imposed inside an obstacle, as the march's stop.
template <class F>
ContinuationResult or_start_failed(F&& march) {
  ContinuationResult result;
  try {
    return march();
  } catch (const IntegrationError& e) {
    result.reason = StopReason::StartFailed;
    result.message = std::string("the initial guess cannot be integrated: ") + e.what();
  } catch (const InfeasibleContact& e) {
    result.reason = StopReason::StartFailed;
    result.message = std::string("infeasible: ") + e.what();
  }
  return result;
}

// A new run (not a resume nor a start from a given point) whose first point could not be corrected
// from the case's guess.
bool from_the_guess_failed(const ContinuationResult& result, const Eigen::VectorXd& start_point, bool resuming) {
  return !resuming && start_point.size() == 0 && result.reason == StopReason::StartFailed && result.points.empty();
}

ContinueRunResult Run::plain(const Eigen::VectorXd& start_point, bool resuming) {
  // The state after every point the march can resume from (right after its row).
  options_.on_resumable = [this](const MarchState& m) {
    set_march_state(&state, m);
    state.saved_row = state.row;
    emit_state(true);
  };
  auto sink_for = [this](const ShootingProblem& problem, int branch, const std::string& phase) -> PointSink {
    const ShootingProblem* at = &problem;
    return [this, at, branch, phase](const ContinuationPoint& p) {
      report(p, branch, phase, &no_contacts_, at);
      if (resumable(p)) {
        state.branch = branch;
        state.phase_condition = phase;
      }
    };
  };
  int branch = state.branch;
  const auto problem = std::make_unique<ShootingProblem>(definition_for(c_, state.phase_condition));
  // Each branch's march is run with the options the uninterrupted run gives it, a resumed one
  // too: branch 0 with the target, the self-passage guard and the stop at the K-th branch point
  // (the count of those passed is in the saved state), branch 1 with bifurcating_branch_options
  // (no target).
  RodContinuationOptions first = options_;
  if (branch == 0 && guard_self_passage(*problem, &first)) note("self-contact: steps through the rod itself are refused");
  if (branch == 0 && r_.switch_at_bp > 0) first.stop_at_branch_point = r_.switch_at_bp;
  if (branch == 1) first = bifurcating_branch_options(options_);
  if (resuming) problem->set_parameter(r_.parameter, state.last.parameter);
  RodContinuation run(*problem, first);
  // (A resume never starts on a branch point: only points the march goes on from are saved.)
  ContinuationResult result = or_start_failed([&] {
    return resuming ? run.resume(march_state(state), sink_for(*problem, branch, state.phase_condition))
                    : run.run(start_point.size() > 0 ? start_point : problem->initial_unknowns(c_.start_guess),
                              sink_for(*problem, 0, state.phase_condition));
  });
  if (from_the_guess_failed(result, start_point, resuming))
    if (const auto h = start_by_homotopy(c_, r_, result.message, [this](const std::string& l) { note(l); }))
      result = or_start_failed([&] { return run.run(h->x, sink_for(*problem, 0, state.phase_condition)); });
  bool switched = branch == 1;  // (a run resumed on the switched branch)
  if (branch == 0 && r_.switch_at_bp > 0 && result.reason != StopReason::TimeLimit) {
    if (result.reason != StopReason::BranchPointStop) {
      finish(true);
      return no_branch_point(result, state.row + 1, r_.switch_at_bp);
    }
    const ContinuationPoint bp = result.points.back();
    branch = 1;
    switched = true;
    const std::string phase = state.phase_condition;
    result = follow_bifurcating_branch(run, bp, options_, r_.switch_side,
                                       [&](const ShootingProblem& p, bool with_phase_condition) {
                                         note(with_phase_condition
                                                  ? "double branch point at " + r_.parameter + " = " +
                                                        text(bp.parameter) +
                                                        ": switching with the axial phase condition"
                                                  : "switching branches at " + r_.parameter + " = " +
                                                        text(bp.parameter));
                                         return sink_for(p, 1, with_phase_condition ? "axial" : phase);
                                       });
  }
  finish(true);
  ContinueRunResult out = stopped(result, state.row + 1, branch);
  out.switch_requested = r_.switch_at_bp > 0;
  out.switched = switched;
  out.ok = out.ok && (!out.switch_requested || switched);
  return out;
}

// Contact: the active set changes along the branch (each change is an event row).
ContinueRunResult Run::with_contacts(const Eigen::VectorXd& start_point, bool resuming) {
  int branch = state.branch;
  std::vector<PointContact> leg_contacts;  // the active set of the leg's points
  auto sink = [&](const ContinuationPoint& p) { report(p, branch, state.phase_condition, &leg_contacts, nullptr); };
  // The leg's state (its active set among it) after every point the run can resume from.
  auto save_leg = [&](const ContactMarchState& m) {
    set_contact_march_state(&state, m);
    state.branch = branch;
    state.saved_row = state.row;
    emit_state(true);
  };
  auto on_active_set = [&](const std::vector<PointContact>& contacts) { leg_contacts = contacts; };
  // As without obstacles: branch 0 to its target or the K-th branch point (counted over its
  // legs), branch 1 from there with no target.
  RodContinuationOptions first = branch == 1 ? bifurcating_branch_options(options_) : options_;
  if (branch == 0) first.stop_at_branch_point = r_.switch_at_bp;
  ContactContinuationResult r;
  r.result = or_start_failed([&] {
    r = resuming ? resume_with_contacts(c_.definition, contact_march_state(state), first, sink, {}, on_active_set,
                                        save_leg)
        : start_point.size() > 0
            ? continue_with_contacts_from(c_.definition, start_point, first, sink, {}, on_active_set, save_leg)
            : continue_with_contacts(c_.definition, c_.start_guess, first, sink, {}, on_active_set, save_leg);
    return r.result;
  });
  if (from_the_guess_failed(r.result, start_point, resuming))
    if (const auto h = start_by_homotopy(c_, r_, r.result.message, [this](const std::string& l) { note(l); })) {
      ProblemDefinition at_start = c_.definition;
      at_start.contacts = h->contacts;
      r.result = or_start_failed([&] {
        r = continue_with_contacts_from(at_start, h->x, first, sink, {}, on_active_set, save_leg);
        return r.result;
      });
    }
  bool switched = branch == 1;  // (a run resumed on the switched branch)
  std::vector<std::string> changes;  // the starting branch's, when the run switched
  if (branch == 0 && r_.switch_at_bp > 0 && r.result.reason != StopReason::TimeLimit) {
    if (r.result.reason != StopReason::BranchPointStop) {
      finish(true);
      ContinueRunResult out = no_branch_point(r.result, state.row + 1, r_.switch_at_bp);
      out.with_contacts = true;
      out.contact_changes = r.changes;
      return out;
    }
    const ContinuationPoint bp = r.result.points.back();
    note("switching branches at " + r_.parameter + " = " + text(bp.parameter));
    branch = 1;
    switched = true;
    changes = std::move(r.changes);
    r = switch_branch_with_contacts(r.definition, bp, r_.switch_side, options_, sink, {}, on_active_set, save_leg);
  }
  finish(true);
  ContinueRunResult out = stopped(r.result, state.row + 1, branch);
  out.with_contacts = true;
  out.contact_changes = std::move(changes);
  out.contact_changes.insert(out.contact_changes.end(), r.changes.begin(), r.changes.end());
  out.switch_requested = r_.switch_at_bp > 0;
  out.switched = switched;
  out.ok = out.ok && (!out.switch_requested || switched);
  return out;
}

// The words (key=value) of two run identities that differ: "saved max_step=1, now max_step=0.5".
std::string identity_difference(const std::string& saved, const std::string& now) {
  const auto words = [](const std::string& text) {
    std::istringstream in(text);
    std::vector<std::string> out;
    for (std::string w; in >> w;) out.push_back(w);
    return out;
  };
  const auto only_in = [](const std::vector<std::string>& a, const std::vector<std::string>& b) {
    std::string out;
    for (const auto& w : a)
      if (std::find(b.begin(), b.end(), w) == b.end()) out += (out.empty() ? "" : " ") + w;
    return out;
  };
  const auto a = words(saved), b = words(now);
  return "saved " + only_in(a, b) + ", now " + only_in(b, a);
}

}  // namespace

std::string ContinueRequest::validate(const Case& c) const {
  if (deflate && (resume || start || switch_at_bp > 0 || seed.ipopt)) return kDeflateRefusal;
  if (deflate && (deflate_max < 1 || deflate_max > 1000)) return "deflate_max must be in [1, 1000]";
  if (const std::string why = seed.validate(); !why.empty()) return why;
  if (start && seed.ipopt) return "--start-from does not combine with --seed";
  if (!c.definition.parameters.contains(parameter))
    return c.path + ": --param " + parameter + ": not a parameter of the case";
  if (const std::string why = dependent_parameter_refusal(c.definition.dependent_parameters, parameter, "continue in");
      !why.empty())
    return c.path + ": --param " + parameter + ": " + why;
  if (!(max_seconds >= 0 && max_seconds <= 1e9)) return "--max-seconds must be in [0, 1e9]";
  if (switch_at_bp < 0) return "switch_at_bp must be >= 0";
  if (direction != 1.0 && direction != -1.0) return "--direction must be 1 or -1 (Python: direction=1 or direction=-1)";
  // With a target the target gives the way; -1 (never the default) asking for the other is refused.
  if (!start && !resume && target && direction < 0 && *target > c.definition.parameters.get(parameter))
    return "--direction -1 points away from --to, which gives the way";
  if (switch_side != 1.0 && switch_side != -1.0) return "--side must be 1 or -1 (Python: side=1 or side=-1)";
  if (switch_side == -1.0 && switch_at_bp == 0)
    return "--side -1 picks a side of a switched branch: it needs --switch-at-bp K (Python: switch_at_bp=K)";
  if (switch_at_bp > 0 && !detect_branch_points)
    return "--switch-at-bp needs branch points: drop --no-branch-points (Python: branch_points=True)";
  for (const auto& e : events) {
    if (!derived_catalogue().count(e.quantity))
      return "--event/--record: '" + e.quantity + "' is not a derived quantity";
    // (A NaN would never be crossed: the event could not fire, and the run would not say so.)
    if (!std::isfinite(e.value) || std::abs(e.value) > case_limits::kMaxMagnitude)
      return "--event/--record: " + e.quantity + "'s value must be finite, within +-1e100";
  }
  if (target && !(std::isfinite(*target) && std::abs(*target) <= case_limits::kMaxMagnitude))
    return "--to must be a finite number within +-1e100 (leave it out for no target)";
  // A target at the starting value is never crossed: the run would march off to its point budget.
  if (!start && !resume && target && *target == c.definition.parameters.get(parameter)) {
    std::ostringstream why;
    why.precision(17);
    why << c.path << ": --to " << *target << " is " << parameter
        << "'s starting value: nothing to continue (start elsewhere with --set " << parameter << "=...)";
    return why.str();
  }
  return options_for(c, *this).validate();
}

ContinueRunResult continue_case(Case c, const ContinueRequest& request, const std::vector<ContinueSink*>& sinks) {
  if (std::string why = request.validate(c); !why.empty()) throw CaseError(why);
  RodContinuationOptions options = options_for(c, request);
  if (request.max_seconds > 0) {
    // One deadline for the whole run: the first solve, every branch and every contact leg.
    limit_wall_clock(c.definition.options, request.max_seconds);
    options.deadline = c.definition.options.newton.deadline;
  }
  const bool resuming = request.resume.has_value();
  Eigen::VectorXd start_point;  // a point of another run: the unknowns to start from
  if (request.start && !resuming) {
    const WrittenPoint& at = *request.start;
    if (!at.contacts.empty() && c.definition.obstacles.empty())
      throw CaseError(request.start_name + ": its point has active contacts, and " + c.path + " has no obstacles");
    c.definition.contacts = at.contacts;  // the active set the point's unknowns belong to
    start_point = at.point.x;
    // The point's unknowns are those of the case with its active set (and the phase condition of
    // a branch switched onto at a double branch point).
    if (const auto n = ShootingProblem(definition_for(c, at.phase_condition)).size(); start_point.size() != n)
      throw CaseError(request.start_name + ": its point has " + std::to_string(start_point.size()) +
                      " unknowns, the case " + std::to_string(n) +
                      " (set the parameters that fix the segments as in that run)");
  }
  if (request.seed.ipopt && !resuming) {
    // The first point from Ipopt's shape and contact set instead of the case's guess.
    DiscreteSeed seed;
    try {
      seed = seed_from_discrete_energy(c.definition, request.seed.segments, request.seed.amplitude);
    } catch (const std::invalid_argument& e) {  // a case the seed does not apply to
      throw CaseError(e.what());
    }
    for (auto* s : sinks) s->note("seed: " + seed.summary);
    c.definition.contacts = seed.contacts;
    c.start_guess = seed.start;
  }

  Run run(c, request, options, sinks);
  RunState& state = run.state;
  state.phase_condition = request.phase_condition.empty() ? "none" : request.phase_condition;
  // A point on a branch followed with the axial phase condition goes on in that problem.
  if (request.start && !resuming && request.start->phase_condition == "axial") state.phase_condition = "axial";
  state.arguments = request.identity;
  int resumed_after = -1;
  if (resuming) {
    if (!request.resume->has_march || request.resume->arguments != request.identity)
      throw CaseError("cannot resume: the state was saved by a run with other arguments, or without the march's "
                      "whole state (resumable_state)");
    state = *request.resume;
    resumed_after = state.row;
    // The rows after the saved point are gone: the last one is the saved point's.
    state.written = WrittenPoint{state.saved_row, state.branch, state.phase_condition, state.last, state.contacts};
  }
  state.parameter_name = request.parameter;
  state.has_set_parameters = true;
  state.set_parameters = request.set_parameters;

  // Solved-for parameters first, then the derived quantities, each once (a case may list an
  // unknown or the continued parameter among its derived quantities too).
  std::vector<std::string> columns;
  for (const std::vector<std::string>* names : {&c.definition.unknown_parameters, &options.derived})
    for (const std::string& name : *names)
      if (name != request.parameter && std::find(columns.begin(), columns.end(), name) == columns.end())
        columns.push_back(name);
  try {
    for (auto* s : sinks) s->begin(request.parameter, columns, resumed_after);
  } catch (const CaseError&) {
    throw;
  } catch (const std::exception& e) {  // an output that cannot be written is bad input
    throw CaseError(e.what());
  }
  ContinueRunResult out = request.deflate                 ? run.deflated()
                          : c.definition.obstacles.empty() ? run.plain(start_point, resuming)
                                                           : run.with_contacts(start_point, resuming);
  out.derived = options.derived;
  return out;
}

RunState resumable_state(const std::string& path, const std::string& identity) {
  RunState saved;
  try {
    saved = load_state(path);
  } catch (const std::runtime_error&) {
    throw;  // no such file
  } catch (const std::exception& e) {  // JSON that is not a state file
    throw CaseError(path + ": not a state file of this command: " + e.what());
  }
  // Without the march's whole state or with other arguments, the resumed run would not be the
  // interrupted one continued: refused, not approximated.
  if (!saved.has_march)
    throw CaseError("cannot resume from " + path +
                    ": it was written by an older kirchhoff that did not save the march's whole state, so a resumed "
                    "run would not repeat the uninterrupted one; run again without --resume");
  if (saved.arguments != identity)
    throw CaseError("cannot resume from " + path + ": it belongs to a run with other arguments (" +
                    identity_difference(saved.arguments, identity) + ")\n  saved: " + saved.arguments +
                    "\n  now:   " + identity);
  return saved;
}

}  // namespace kirchhoff
