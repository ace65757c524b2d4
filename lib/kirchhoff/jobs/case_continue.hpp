// Continuing a case in one parameter as `kirchhoff continue` and Python's Case.continue_() both
// do, so that neither front end decides how: the one place that
//   - chooses plain continuation (continuation.hpp) or continuation through changes of the
//     active contact set (contact.hpp) by whether the case has obstacles;
//   - adds the axial phase condition for runs that ask for it (and for a branch switched onto at
//     the double branch point of a spatial rod), and refuses steps through the rod itself when it
//     has self-contact (self_passage.hpp);
//   - switches onto the branch bifurcating at the K-th branch point;
//   - makes every event quantity a derived quantity of each point;
//   - follows every branch through the equilibria at the start with `deflate`
//     (deflated_continuation.hpp);
//   - starts from the case's guess, from Ipopt's seed, from another run's point, or resumes a
//     run from its state (run_state.hpp), taking the same steps as the uninterrupted run;
//   - decides whether the run ended normally (ended_normally).
// Points, notes and the run's state go to sink objects (continue_outputs.hpp has the branch CSV,
// the state file and the profiles); a front end maps its arguments onto a ContinueRequest and
// prints what the sinks and the result say.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/run_state.hpp"

namespace kirchhoff {

// Whether a continuation that stopped for `reason` ended normally: at its target, a bound, its
// point budget, a stop event, a fold or branch point it was asked to stop at. Not normal (the
// CLI's exit status 1, Python's Branch.ok false): the start did not converge (start_failed), the
// step fell below its minimum (step_too_small), a point broke complementarity (inadmissible),
// or the wall-clock limit stopped it before any of these (time_limit: resumable, not finished).
bool ended_normally(StopReason reason);

struct ContinueRequest {
  std::string parameter;  // the continued parameter: a [parameters] name, not a dependent one
  // Stop on reaching it (none: no target). Finite and within +-1e100 where given: a NaN target
  // was taken for none, and `--to nan` marched on to the point budget reporting success.
  std::optional<double> target;
  double direction = 1.0;     // initial direction of the parameter (+1/-1) when there is no target
  double initial_step = 0.05;  // pseudo-arclength steps (RodContinuationOptions)
  double min_step = 1e-7;
  double max_step = 0.5;
  int max_points = 500;
  int samples = 101;  // profile points per point for invariants and derived quantities
  bool detect_branch_points = true;
  bool compute_stability = true;
  // Stop (stop = true) or record crossings of derived quantities (derived_catalogue() names);
  // each quantity is computed at every point and written with the others.
  std::vector<ContinuationEvent> events;
  int switch_at_bp = 0;       // > 0: switch onto the branch bifurcating at the K-th branch point
  double switch_side = 1.0;   // +1 / -1: which side of the bifurcating branch
  double max_seconds = 0.0;   // wall-clock limit of the whole run (0: none); stops as time_limit
  // "" or "none": the case's problem; "axial": with the axial phase condition (as the case was
  // loaded with it).
  std::string phase_condition;
  // Every branch through the equilibria found at the start (at most deflate_max), branch k from
  // the k-th by energy. Not with switch_at_bp, seed, start or resume.
  bool deflate = false;
  int deflate_max = 16;
  StartSeed seed;  // ipopt: the first point from Ipopt's shape and contact set (not on resume)
  // A point of another run to start from (its unknowns, active set and phase condition), the
  // case loaded with that run's parameter values (plan_start_from).
  std::optional<WrittenPoint> start;
  std::string start_name;  // where `start` comes from (a state file), for messages
  // The state of an interrupted run to resume (resumable_state): the run goes on from its last
  // saved point, taking the steps the uninterrupted run took.
  std::optional<RunState> resume;
  // What identifies the run (a front end's arguments that decide its points): recorded in the
  // state, and a resume whose state records another is refused.
  std::string identity;
  // The run's parameter values beyond the case file's, recorded in the state (a run started from
  // this one keeps them).
  ParameterOverrides set_parameters;

  // "" when the request can be run on `c`, else what is wrong (the front ends raise it as bad
  // input: exit status 2, ValueError).
  std::string validate(const Case& c) const;
};

// Refusal of deflate with what it does not combine with (validate; plan_run says it before it
// reads a state file).
extern const char kDeflateRefusal[];

// A point as the run reports it.
struct RunPoint {
  int row = 0;     // its index among all points of the run (continuous across branches)
  int branch = 0;  // 0: the starting branch; 1: after switching; deflate: the start's rank
  const ContinuationPoint* point = nullptr;
  const std::string* phase_condition = nullptr;         // of the problem it belongs to
  const std::vector<PointContact>* contacts = nullptr;  // contact runs: its leg's active set
  // The problem it belongs to (plain runs), null for contact runs (their leg's problem is the
  // case's definition with `contacts`).
  const ShootingProblem* problem = nullptr;
};

// Where a run's output goes. Every method has an empty default; a run calls them in order:
// begin, then per point `point` and, where the march can be resumed, `state`; notes between them;
// `finish` last (when the run ended by a status, not by an exception).
class ContinueSink {
 public:
  virtual ~ContinueSink() = default;
  // The run's columns: the continued parameter's name and the per-point quantities (solved-for
  // parameters first, then the derived quantities); `resumed_after_row`: the last row kept from
  // the interrupted run (-1: a new run).
  virtual void begin(const std::string& parameter, const std::vector<std::string>& columns, int resumed_after_row) {
    (void)parameter, (void)columns, (void)resumed_after_row;
  }
  virtual void point(const RunPoint& p) { (void)p; }
  // One line of what the run did (switching branches, the self-passage guard, a branch of a
  // deflated run starting, the seed, a change of the active set...).
  virtual void note(const std::string& line) { (void)line; }
  // The run's state after the point just reported, when the run is resumable (not deflate).
  // `resumable`: the march can go on from this point (a state saved at any call resumes, from
  // the last resumable point it holds).
  virtual void state(const RunState& s, bool resumable) { (void)s, (void)resumable; }
  // The state at the end of the run (resumable runs), then the end.
  virtual void finish(const RunState* s) { (void)s; }
};

// One branch of a deflated run.
struct DeflatedBranchOutcome {
  int rank = 0;
  StopReason reason = StopReason::MaxPoints;
  std::string message;
  std::vector<std::string> contact_changes;
};

struct ContinueRunResult {
  // The status word: to_string(reason), or "no_equilibrium" (deflate found none).
  std::string status;
  StopReason reason = StopReason::MaxPoints;
  std::string message;
  // What the run counts as success (the CLI's exit status 0, Python's Branch.ok): ended_normally
  // (every branch's, with deflate), the switch made when switch_at_bp asked for it, at least one
  // branch with deflate.
  bool ok = false;
  int points = 0;       // rows reported
  // The derived quantities of every point (the case's, then each event's quantity it lacks): the
  // columns after the solved-for parameters.
  std::vector<std::string> derived;
  int last_branch = 0;
  bool with_contacts = false;  // the case has obstacles: the run went through contact legs
  bool switch_requested = false;
  bool switched = false;
  int refused_steps = 0;                     // steps refused by the self-passage guard
  // Contact runs: one line per change of the active set, both branches' when it switched (the
  // event rows say which event: obstacle_reached, contact_flattens, ...; these lines say where
  // and what changed).
  std::vector<std::string> contact_changes;
  // deflate: the equilibria at the start and why their search stopped, and each branch.
  int equilibria = 0;
  std::string search_stopped_because;
  std::vector<DeflatedBranchOutcome> branches;
};

// Runs the request on a loaded case. Throws CaseError for a request validate() refuses (or a
// resume state of another run, a start point of another problem, outputs that cannot be
// opened, a case Ipopt's seed does not apply to); std::runtime_error when Ipopt's seed does not
// converge. A start that cannot be
// integrated or is imposed inside an obstacle is a result (start_failed), as is every other stop
// of the march; other exceptions of the march propagate (with the sinks' points so far written).
ContinueRunResult continue_case(Case c, const ContinueRequest& request, const std::vector<ContinueSink*>& sinks);

// The state of an interrupted run, checked to be resumable by a run of `identity`: throws
// CaseError naming `path` when it was written without the march's whole state or by a run with
// another identity; std::runtime_error / nlohmann's exceptions when it cannot be read.
RunState resumable_state(const std::string& path, const std::string& identity);

}  // namespace kirchhoff
