#include "kirchhoff/sweeps/plectoneme_sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <optional>
#include <sstream>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/contact/hard_self_contact.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/contact/self_passage.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/run_state.hpp"

namespace kirchhoff {
namespace {

// Columns of a plectoneme branch: the case's measures, then what Fig. 11 plots and the closed
// forms beside them (NaN where there is no ply, theta outside (0, pi/4)).
const std::vector<std::string> kMeasured = {"T_ext", "helix_angle", "helix_radius", "m3", "contact_pressure",
                                            "contact_start", "contact_end", "H_A", "H_B", "self_distance",
                                            "loop_clearance"};

// The closed forms of a ply of helix angle theta and radius rho (the R of eqs. 58-61): T rho^2/EI by
// (61) and m3 by (58b); NaN when there is no ply (theta outside (0, pi/4)).
struct HelixFormulas {
  double eq61 = NAN, m3_eq58b = NAN;
};
HelixFormulas helix_formulas(double theta, double rho, double EI) {
  if (!(theta > 0.0 && theta < 0.25 * M_PI && rho > 0.0)) return {};
  return {analytic::plectoneme_end_tension(theta, 1.0, 1.0), analytic::helix_twisting_moment(theta, EI, rho)};
}

// The hard-contact ply's columns (--hard-from): the same measures, rho = R exactly, and what
// complementarity watches (contact forces, the line's pressure, the gaps between contacts).
const std::vector<std::string> kHardMeasured = {"T_ext",         "helix_angle",       "helix_radius",
                                                "m3",            "contact_pressure",  "contact_start",
                                                "contact_end",   "H_A",               "H_B",
                                                "self_distance", "min_contact_force", "min_wrap_pressure",
                                                "ply_clearance", "contact_count"};

// A progress line to options.progress (nothing when it is not set), its parts streamed as
// std::cerr would print them.
template <class... Parts>
void progress_line(const PlectonemeRunOptions& options, const Parts&... parts) {
  if (!options.progress) return;
  std::ostringstream line;
  (line << ... << parts);
  options.progress(line.str());
}

std::map<std::string, double> columns(const ContinuationPoint& p, double EI, const std::vector<std::string>& measured) {
  std::map<std::string, double> c;
  for (const auto& name : measured) c[name] = p.derived.count(name) ? p.derived.at(name) : NAN;
  const double theta = c["helix_angle"], rho = c["helix_radius"];
  // rho, the strands' distance to the axis, is the helix radius R of eqs. (58)-(61).
  c["T_rho2_over_EI"] = c["T_ext"] * rho * rho / EI;
  const HelixFormulas formulas = helix_formulas(theta, rho, EI);
  c["eq61"] = formulas.eq61;
  c["m3_eq58b"] = formulas.m3_eq58b;
  return c;
}

// The fields of one CSV line (the branch CSVs quote nothing: their text fields hold no commas).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
  return fields;
}

// The CSV ends with its endpoint row (its `type` column): the branch was followed to its target.
// A file without a `type` column, or with a last row cut short before it, is not complete.
bool branch_complete(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  const std::vector<std::string> names = csv_fields(header), fields = csv_fields(last);
  const auto type = std::find(names.begin(), names.end(), "type");
  const auto column = static_cast<size_t>(type - names.begin());
  return type != names.end() && column < fields.size() && fields[column] == "endpoint";
}

// Forces, and with them the unknowns, the pseudo-arclength and the residual's round-off, scale as
// EI/R^2: relative to L/2R = 100, for which the case and the step defaults are set.
double force_scale(double slenderness) { return (slenderness / 100.0) * (slenderness / 100.0); }

// The case's tolerance is for L/2R = 100 (forces up to ~1e3); at L/2R = 1000 (forces ~1e4) a fixed
// 1e-8 is below the residual's round-off (1.8e-8 measured near 37 turns): Newton's line search
// fails and the continuation's steps collapse. So the solver's tolerance (and the corrector's,
// below) scale like the forces.
ProblemDefinition with_scaled_tolerance(ProblemDefinition d, double slenderness) {
  d.options.newton.residual_tolerance *= force_scale(slenderness);
  return d;
}

// A barrier branch's problem: the tolerance scaled with the forces and the variational equations
// at options.sensitivity_tol (IntegratorOptions; the sweep 2.25 times faster, its branch ends the
// same to 10-12 digits). Not for the exact ply's first solve from its seed: at 1e-8 Newton
// diverged there (an integration underflow by the third iteration); its legs use it
// (follow_hard_legs).
ProblemDefinition barrier_definition(ProblemDefinition d, double slenderness, const PlectonemeRunOptions& options) {
  if (options.sensitivity_tol > 0) d.options.integrator.sensitivity_tol = options.sensitivity_tol;
  return with_scaled_tolerance(std::move(d), slenderness);
}

// How a ply of `problem` (at its current parameters) is followed in any parameter at this
// slenderness (steps scaled with the forces), every step checked for passing the rod through itself.
RodContinuationOptions ply_continuation(const ShootingProblem& problem, const std::string& parameter, double target,
                                     double slenderness, const PlectonemeRunOptions& options) {
  RodContinuationOptions o;
  o.parameter = parameter;
  o.target = target;
  o.initial_step = 1.0 * force_scale(slenderness);
  o.max_step = options.max_step * force_scale(slenderness);
  o.max_points = 20000;
  // A point's Jacobian (13 sensitivities per segment) costs about fifty residual evaluations
  // (perf at L/2R = 200: 85 % of a run in the variational equations, 2 % in residuals), so the
  // steps are long and a corrector's iterations cheap: a point whose chord iterations converged
  // keeps the previous matrix (reuse_jacobian), and modified Newton keeps a matrix while the
  // residual halves, on steps that grow while they take up to 10 iterations (L/2R = 200 to 8
  // turns: 145 s -> 33 s, the same end point to 12 digits). Long steps are safe only with the
  // SelfPassageGuard attached below: at L/2R = 500 the branch folds sharply at 1.034 turns,
  // and a step that suits the rest of the branch crosses that fold onto the sheet where the rod
  // has passed through itself (every run before the guard, full or modified Newton, did: their
  // ply formed two turns late, T_ext at 20 turns 3063 instead of 3882).
  if (options.modified_newton) {
    o.modified_newton = true;
    o.corrector_max_iterations = 16;
    o.grow_iterations = 10;
    o.shrink_iterations = 14;
  } else {
    o.corrector_max_iterations = 12;
    o.grow_iterations = 6;
    o.shrink_iterations = 10;
  }
  o.reuse_jacobian_iterations = options.reuse_jacobian;
  o.detect_branch_points = false;  // the barrier's stiffness turns the determinant's sign into noise
  guard_self_passage(problem, &o);
  return o;
}

// How a plectoneme branch is followed in `turns`, with the case's measures at every point.
RodContinuationOptions continuation_options(const ShootingProblem& problem, const Case& c, double slenderness,
                                         double turns_max, const PlectonemeRunOptions& options) {
  RodContinuationOptions o = ply_continuation(problem, "turns", turns_max, slenderness, options);
  o.corrector_tolerance = std::max(1e-10, c.definition.options.newton.residual_tolerance) * force_scale(slenderness);
  o.derived = c.derived;
  o.samples = 10 * static_cast<int>(slenderness) + 1;  // R/10 apart on the half rod: the ply's pitch is 10-30 R
  return o;
}

}  // namespace

namespace {

std::vector<std::string> csv_names(const std::vector<std::string>& measured) {
  std::vector<std::string> n = measured;
  for (const char* extra : {"T_rho2_over_EI", "eq61", "m3_eq58b"}) n.push_back(extra);
  return n;
}

// The hard-contact re-solutions of a branch's ply points (opt-in): one row per re-solved point,
// keyed by the branch CSV's row index so that a resume truncates both alike.
class HardContactCsv {
 public:
  HardContactCsv(const std::string& path, const ShootingProblem& problem, double EI, const PlectonemeRunOptions& options,
                 int resumed_row, PlectonemeBranchSummary* summary)
      : problem_(problem), EI_(EI), options_(options), summary_(summary) {
    const bool resuming = resumed_row >= 0 && std::filesystem::exists(path);
    if (resuming) truncate_csv(path, resumed_row, "", CsvRows::SomeIndices);
    csv_.open(path, resuming ? std::ios::app : std::ios::trunc);
    if (!csv_) throw std::runtime_error("cannot write " + path);
    csv_ << std::setprecision(12);
    if (!resuming)
      csv_ << "index,turns,T_ext_barrier,T_ext,helix_angle,T_R2_over_EI,eq61,m3,m3_eq58b,contact_pressure,"
              "contact_start,contact_end,min_gap,min_force,complementarity,energy,segments,rounds,iterations,"
              "seconds,status\n";
  }

  // Re-solves point p (row `row` of the branch CSV, a point of the problem's branch in turns) when
  // it has a ply and is far enough from the last re-solved point, or ends the branch.
  void consider(const ContinuationPoint& p, int row, const std::map<std::string, double>& barrier) {
    const bool ply = !std::isnan(barrier.at("eq61"));
    const bool due = std::isnan(last_turns_) || std::abs(p.parameter - last_turns_) >= options_.hard_contact_every ||
                     p.type == PointType::Endpoint;
    if (!ply || !due) return;
    const auto started = std::chrono::steady_clock::now();
    ShootingProblem at = problem_;
    at.set_parameter("turns", p.parameter);
    HardSelfContactOptions o;
    o.spacing = options_.hard_spacing;
    const HardSelfContactPlectoneme h = solve_hard_self_contact(at, p.x, o);
    const double R = h.radius;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const HelixFormulas formulas = h.converged ? helix_formulas(h.helix_angle, R, EI_) : HelixFormulas{};
    csv_ << row << ',' << p.parameter << ',' << barrier.at("T_ext") << ',' << h.T_ext << ',' << h.helix_angle << ','
         << h.T_ext * R * R / EI_ << ',' << formulas.eq61 << ',' << h.m3 << ',' << formulas.m3_eq58b << ','
         << h.contact_pressure
         << ',' << h.contact_start << ',' << h.contact_end << ',' << h.min_gap << ',' << h.min_force << ','
         << h.complementarity << ',' << h.energy << ',' << h.segments << ',' << h.rounds << ',' << h.iterations << ','
         << seconds << ",\"" << h.status << "\"\n"
         << std::flush;
    last_turns_ = p.parameter;
    ++summary_->hard_points;
    summary_->hard_failures += h.converged ? 0 : 1;
    summary_->hard_seconds += seconds;
  }

 private:
  const ShootingProblem& problem_;
  double EI_;
  PlectonemeRunOptions options_;
  PlectonemeBranchSummary* summary_;
  std::ofstream csv_;
  double last_turns_ = NAN;
};

// One slenderness's CSV, written point by point (flushed), with the state to resume from beside it.
class BranchCsv {
 public:
  BranchCsv(const std::string& csv_path, double EI, double slenderness, const PlectonemeRunOptions& options,
            PlectonemeBranchSummary* summary, std::vector<std::string> measured = kMeasured)
      : state_path_(csv_path + ".state.json"),
        EI_(EI),
        slenderness_(slenderness),
        options_(options),
        summary_(summary),
        measured_(std::move(measured)) {
    const bool resuming = options.resume && std::filesystem::exists(state_path_);
    if (resuming) {
      state_ = load_state(state_path_);
      truncate_csv(csv_path, state_.saved_row);
    }
    state_.parameter_name = "turns";
    csv_.open(csv_path, resuming ? std::ios::app : std::ios::trunc);
    if (!csv_) throw std::runtime_error("cannot write " + csv_path);
    csv_ << std::setprecision(12);
    if (!resuming) {
      csv_ << "index,turns,type";
      for (const auto& n : csv_names(measured_)) csv_ << ',' << n;
      csv_ << ",newton_iterations,step\n";
    }
    resumed_ = resuming;
  }

  bool resumed() const { return resumed_; }
  RunState& state() { return state_; }

  // With options.hard_contact_every > 0, ply points of `problem`'s branch in turns are re-solved
  // with hard self-contact into the _hard.csv beside this one.
  void follow_hard_contact(const std::string& csv_path, const ShootingProblem& problem) {
    if (!(options_.hard_contact_every > 0)) return;
    const std::string path = csv_path.substr(0, csv_path.size() - 4) + "_hard.csv";
    hard_.emplace(path, problem, EI_, options_, resumed_ ? state_.saved_row : -1, summary_);
  }

  void operator()(const ContinuationPoint& p) {
    const auto row = columns(p, EI_, measured_);
    csv_ << ++state_.row << ',' << p.parameter << ',' << to_string(p.type);
    for (const auto& n : csv_names(measured_)) csv_ << ',' << row.at(n);
    csv_ << ',' << p.newton_iterations << ',' << p.step << '\n' << std::flush;
    if (hard_) hard_->consider(p, state_.row, row);
    if (resumable(p)) save_resume_point(state_path_, p, &state_);
    ++summary_->points;
    if (!std::isnan(row.at("eq61"))) {
      summary_->last = row;
      summary_->last["turns"] = p.parameter;
      summary_->ply.push_back(summary_->last);
    }
    if (options_.progress_every > 0 && summary_->points % options_.progress_every == 0)
      progress_line(options_, "  L/2R = ", slenderness_, "  point ", state_.row, "  turns = ", std::setprecision(6),
                    p.parameter);
    if (options_.after_point) options_.after_point();
  }

 private:
  std::filesystem::path state_path_;
  double EI_, slenderness_;
  PlectonemeRunOptions options_;
  PlectonemeBranchSummary* summary_;
  std::vector<std::string> measured_;
  RunState state_;
  std::ofstream csv_;
  bool resumed_ = false;
  std::optional<HardContactCsv> hard_;
};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string stop_text(const ContinuationResult& r) {
  return to_string(r.reason) + (r.message.empty() ? "" : " (" + r.message + ")");
}

// Branch 0: from `start` up to turns_max; branch 1: from the same start down to turns_min, both
// into `csv` (a resumed CSV resumes the leg it was in). Returns "up: ...; down: ..." and counts
// the refused steps into *refused.
std::string follow_up_and_down(ShootingProblem& problem, BranchCsv& csv, const ContinuationPoint& start,
                               double turns_min, double turns_max,
                               const std::function<RodContinuationOptions(double target)>& options_to, int* refused) {
  auto sink = [&](const ContinuationPoint& p) { csv(p); };
  const int first_leg = csv.resumed() ? csv.state().branch : 0;
  std::string stops;
  for (int leg = first_leg; leg < 2; ++leg) {
    const RodContinuationOptions o = options_to(leg == 0 ? turns_max : turns_min);
    const bool resume_leg = csv.resumed() && leg == first_leg;
    csv.state().branch = leg;
    ContinuationResult r;
    if (resume_leg) {
      problem.set_parameter("turns", csv.state().last.parameter);
      r = RodContinuation(problem, o).resume(csv.state().last, sink);
    } else {
      problem.set_parameter("turns", start.parameter);
      r = RodContinuation(problem, o).run(start.x, sink);
    }
    stops += (stops.empty() ? "" : "; ") + std::string(leg == 0 ? "up: " : "down: ") + stop_text(r);
    *refused += r.refused_steps;
  }
  return stops;
}

}  // namespace

namespace {

// The hard-contact ply's problem: the barrier case's definition at `turns` with exact self-contact
// where `start` says (its contacts and segments per piece), tolerances scaled with the forces, the
// variational equations at sensitivity_tol (0: the case's).
ShootingProblem hard_ply_problem(const Case& c, double slenderness, const RunState& start,
                                 double sensitivity_tol = 0.0) {
  ProblemDefinition barrier = c.definition;
  if (sensitivity_tol > 0) barrier.options.integrator.sensitivity_tol = sensitivity_tol;
  barrier.parameters.set("turns", start.last.parameter);
  ProblemDefinition d = hard_ply_definition(barrier, start.contacts);
  d.piece_segments = start.piece_segments;  // x's layout (set by length where x was solved)
  d.options.segments = std::accumulate(d.piece_segments.begin(), d.piece_segments.end(), 0);
  return ShootingProblem(with_scaled_tolerance(d, slenderness));
}

// Where a hard-contact ply leg stops: the contact set would change there (not followed), or the
// rod would pass through itself away from the ply's contacts.
std::vector<ContinuationEvent> complementarity_events() {
  return {{"min_contact_force", 0.0, true, "a contact lifts off (its force reaches 0)"},
          {"min_wrap_pressure", 0.0, true, "the line contact's pressure reaches 0 inside it"},
          {"ply_clearance", 0.0, true, "a new contact forms between the ply's contacts"},
          {"self_distance", 1.0 - kSelfDistanceSlack, true, "the rod reaches itself away from the ply's contacts"}};
}

// The hard-contact ply legs from `start` (a solved exact ply at start.last.parameter turns, its
// contacts and segments per piece): followed in turns up to turns_max (branch 0) and from the same
// start down to turns_min (branch 1) into hard_csv, each leg stopping where complementarity would
// fail; a resumed run resumes the leg it was in. (Re-segmenting a leg every turn as its line
// contact lengthens was tried: the same end points, 1.7-3 times slower at L/2R = 200.)
void follow_hard_legs(const Case& c, double slenderness, const RunState& start, double turns_min, double turns_max,
                      const std::string& hard_csv, const PlectonemeRunOptions& options,
                      PlectonemeBranchSummary* summary) {
  // The legs continue from a solved start, so their Jacobian can be looser (L/2R = 100, 5 -> 10
  // and 5 -> 4 turns at 1e-8: 32.9 s -> 17.7 s, T_ext at the ends equal to 11 digits, the contact
  // forces to 2e-9); the start's own solve from its seed keeps the case's.
  ShootingProblem problem = hard_ply_problem(c, slenderness, start, options.sensitivity_tol);
  PlectonemeBranchSummary legs;
  BranchCsv csv(hard_csv, c.definition.parameters.get("EI"), slenderness, options, &legs, kHardMeasured);
  csv.state().contacts = start.contacts;
  csv.state().piece_segments = start.piece_segments;
  summary->hard_ply_stop = follow_up_and_down(
      problem, csv, start.last, turns_min, turns_max,
      [&](double target) {
        RodContinuationOptions o = continuation_options(problem, c, slenderness, target, options);
        o.max_step = options.ply_max_step * force_scale(slenderness);
        o.derived = kHardMeasured;
        o.events = complementarity_events();
        return o;
      },
      &legs.refused_steps);
  summary->hard_ply_points += legs.points;
  summary->hard_ply = legs.ply;
  summary->refused_steps += legs.refused_steps;
}

// A CSV whose both legs (up and down in turns) are done is left alone by a resumed run.
bool both_legs_complete(const std::string& csv, const PlectonemeRunOptions& options) {
  return options.resume && branch_complete(csv) && std::filesystem::exists(csv + ".state.json") &&
         load_state(csv + ".state.json").branch == 1;
}

// The start of a hard ply's legs at `turns`: `seed` solved, tolerances scaled with the forces.
// Throws "<what> did not solve: ..." when it does not.
RunState solved_start(const HardPlyStart& seed, double slenderness, double turns, const std::string& what) {
  const ShootingProblem hard(with_scaled_tolerance(seed.definition, slenderness));
  const ShootingResult solved = solve(hard, seed.x);
  if (!solved.summary.converged())
    throw std::runtime_error(what + " did not solve: " + solved.summary.brief_report());
  RunState start;
  start.parameter_name = "turns";
  start.last.parameter = turns;
  start.last.x = solved.x;
  start.contacts = hard.contacts_at(solved.x);
  start.piece_segments = hard.piece_segments();
  return start;
}

// The barrier ply is handed to exact contact once its strands are at most this far apart (in 2R),
// stiffened to it by continuation in log_softness; when the exact ply's Newton solve does not
// converge from there, the next, closer gap is tried. Why so close: the exact ply's Newton solve
// starts from the barrier's states, and its basin is narrow (measured at L/2R = 300 and 5 turns,
// where the case's log_softness -4 leaves 1.324: from 1.05 Newton stalls at a residual of 62 after
// 50 iterations, from 1.02 its Jacobian turns singular, from 1.01 it converges in 5 iterations and
// from 1.002, log_softness -7.8, in 3, the whole handover then fastest: Ipopt too starts nearer its
// minimum, 56 iterations against 196 from 1.05). At L/2R = 100 the case's -4 leaves 1.108 and
// Newton converged from there, but not at 300: the gap a fixed log_softness leaves grows with
// the slenderness, so the stiffness is chosen by the gap, not set. At L/2R = 500 and 15 turns, a
// ply 173 R long, the first gap is not enough (Newton stalls at a residual of 3.96 after 50
// iterations) and the second is (measured; docs/plectonemes.md).
constexpr double kHandoverSelfDistances[] = {1.002, 1.0005};
// The stiffening stops here: a ply whose strands the barrier still holds further apart is not
// handed over (a branch without a ply at these turns never gets there).
constexpr double kStiffestLogSoftness = -10.0;

// The barrier ply's self_distance (in 2R) at x: the smallest distance between its strands.
double barrier_self_distance(const ShootingProblem& barrier, const Eigen::VectorXd& x, double slenderness) {
  ShootingResult at;
  at.x = x;
  at.summary.status = SolverStatus::Converged;
  at.parameters = barrier.parameters_at(x);
  return make_solution(barrier, at, 10 * static_cast<int>(slenderness) + 1, {"self_distance"})
      .derived.at("self_distance");
}

// The barrier ply `at` (at `turns`) stiffened until its strands are at most `gap` x 2R apart: continued in
// log_softness towards kStiffestLogSoftness, stopping at the event self_distance = gap. A ply already that
// close is returned as it is. Sets `barrier`'s log_softness to the returned point's. Throws when the
// stiffest barrier still holds the strands further apart or the continuation stops short.
ContinuationPoint stiffened_to(ShootingProblem& barrier, const ContinuationPoint& at, double gap, double slenderness,
                               const PlectonemeRunOptions& options) {
  const double distance = barrier_self_distance(barrier, at.x, slenderness);
  const double log_softness = barrier.parameters().get("log_softness");
  progress_line(options, "  the barrier ply at turns = ", at.parameter, ", log_softness ", std::setprecision(6),
                log_softness, ": self_distance ", distance);
  if (distance <= gap) return at;
  // Continued like the barrier branch (its Jacobian at sensitivity_tol); `barrier` itself keeps the
  // case's, as the exact ply made from it must for its first solve.
  ProblemDefinition loose = barrier.definition();
  if (options.sensitivity_tol > 0) loose.options.integrator.sensitivity_tol = options.sensitivity_tol;
  ShootingProblem moving(loose);
  RodContinuationOptions o = ply_continuation(moving, "log_softness", kStiffestLogSoftness, slenderness, options);
  o.derived = {"self_distance"};
  o.samples = 10 * static_cast<int>(slenderness) + 1;  // R/10 apart, as on the branch
  o.events = {{"self_distance", gap, true, "the strands within the handover's gap"}};
  const ContinuationResult r = RodContinuation(moving, o).run(at.x);
  if (r.reason != StopReason::EventStop || r.points.empty()) {
    std::ostringstream e;
    e << "the barrier ply (self_distance " << distance << " at log_softness " << log_softness
      << ") did not stiffen to self_distance " << gap << " by log_softness " << kStiffestLogSoftness << ": "
      << stop_text(r) << (r.reason == StopReason::ReachedTarget ? " (is there a ply at these turns?)" : "");
    throw std::runtime_error(e.str());
  }
  ContinuationPoint stiff = r.points.back();
  barrier.set_parameter("log_softness", stiff.parameter);
  progress_line(options, "  stiffened to log_softness ", stiff.parameter, " (", r.points.size(), " steps)");
  stiff.parameter = at.parameter;
  return stiff;
}

// The exact ply's start from the barrier ply `at` (of `barrier`, at its parameters): the contact set
// read off the discretised hard solution (Ipopt, seeded by it), the shooting problem with exact
// self-contact solved from the barrier's states. Throws "hard contact at turns = ...: ..." when either
// does not solve.
RunState exact_ply_start(const ShootingProblem& barrier, const ContinuationPoint& at, double slenderness,
                         const PlectonemeRunOptions& options) {
  const std::string where = "hard contact at turns = " + std::to_string(at.parameter);
  HardSelfContactOptions discrete_options;
  discrete_options.spacing = options.hard_spacing;
  const HardSelfContactPlectoneme discrete = solve_hard_self_contact(barrier, at.x, discrete_options);
  if (!discrete.converged)
    throw std::runtime_error(where + ": the discretised hard problem (Ipopt), whose contacts seed the shooting, did not "
                             "solve: " + discrete.status +
                             " (a thinner rod's exact ply is reached from a thicker one's: --from-ply)");
  const HardPlyStart seed = hard_ply_from_barrier(barrier, at.x, ply_contacts(discrete));
  return solved_start(seed, slenderness, at.parameter,
                      where + ": the shooting problem with the discretised solution's " +
                          std::to_string(seed.definition.contacts.size()) + " contacts");
}

// The hard-contact ply legs of a branch (--hard-from): from the barrier solution `at` (a ply),
// stiffened until its strands nearly touch, the exact ply solved from it (exact_ply_start; from
// each of kHandoverSelfDistances in turn until it solves), then follow_hard_legs. The start is saved
// beside hard_csv (+ ".start.json"), so a resumed run skips the re-solution.
void follow_hard_ply(const Case& c, double slenderness, const ContinuationPoint& at, double turns_min,
                     double turns_max, const std::string& hard_csv, const PlectonemeRunOptions& options,
                     PlectonemeBranchSummary* summary) {
  const auto started = std::chrono::steady_clock::now();
  const std::string start_path = hard_csv + ".start.json";
  if (both_legs_complete(hard_csv, options)) {
    summary->hard_ply_stop = "already complete";
    return;
  }
  RunState start;
  if (options.resume && std::filesystem::exists(start_path)) {
    start = load_state(start_path);
  } else {
    ShootingProblem barrier(with_scaled_tolerance(c.definition, slenderness));
    barrier.set_parameter("turns", at.parameter);
    ContinuationPoint stiff = at;
    std::string failures;
    for (double gap : kHandoverSelfDistances) {
      stiff = stiffened_to(barrier, stiff, gap, slenderness, options);
      try {
        start = exact_ply_start(barrier, stiff, slenderness, options);
        failures.clear();
        break;
      } catch (const std::runtime_error& e) {
        progress_line(options, "  ", e.what());
        failures += (failures.empty() ? "" : "; ") + ("from self_distance " + std::to_string(gap) + ": ") + e.what();
      }
    }
    if (!failures.empty())
      throw std::runtime_error("the handover of the barrier ply to exact contact failed from every gap tried: " +
                               failures);
    save_state(start_path, start);
  }
  follow_hard_legs(c, slenderness, start, turns_min, turns_max, hard_csv, options, summary);
  summary->hard_ply_seconds += seconds_since(started);
}

}  // namespace

PlectonemeBranchSummary follow_plectoneme_branch(const std::string& case_path, double slenderness, double turns_max,
                                                 const std::string& csv_path, const PlectonemeRunOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  PlectonemeBranchSummary summary;
  const Case c = load_case(case_path, {{"slenderness", slenderness}});
  // With --hard-from the barrier leg ends there and hands its ply to exact contact.
  const bool hard = options.hard_from > 0.0 && options.hard_from < turns_max;
  const std::string end_path = csv_path + ".end.json";  // the barrier leg's last point, where hard legs start
  std::optional<ContinuationPoint> end;
  if (options.resume && branch_complete(csv_path)) {
    summary.stop = "already complete";
    if (hard && std::filesystem::exists(end_path)) end = load_state(end_path).last;
  } else {
    ShootingProblem problem(barrier_definition(c.definition, slenderness, options));
    const RodContinuationOptions o =
        continuation_options(problem, c, slenderness, hard ? options.hard_from : turns_max, options);
    BranchCsv csv(csv_path, c.definition.parameters.get("EI"), slenderness, options, &summary);
    csv.follow_hard_contact(csv_path, problem);
    auto sink = [&](const ContinuationPoint& p) { csv(p); };
    RodContinuation run(problem, o);
    ContinuationResult branch;
    if (csv.resumed()) {
      problem.set_parameter(o.parameter, csv.state().last.parameter);
      branch = run.resume(csv.state().last, sink);
    } else {
      const ShootingResult untwisted = solve(problem, problem.initial_unknowns(c.start_guess));
      if (!untwisted.summary.converged())
        throw std::runtime_error(case_path + ": the untwisted rod does not solve: " + untwisted.summary.brief_report());
      branch = run.run(untwisted.x, sink);
    }
    summary.stop = stop_text(branch);
    summary.refused_steps = branch.refused_steps;
    if (hard && branch.reason == StopReason::ReachedTarget) {
      end = branch.points.back();
      RunState at_end;
      at_end.parameter_name = "turns";
      at_end.last = *end;
      save_state(end_path, at_end);
    }
  }
  summary.seconds = seconds_since(started);
  if (hard) {
    if (end)
      follow_hard_ply(c, slenderness, *end, options.hard_turns_min, turns_max,
                      csv_path.substr(0, csv_path.size() - 4) + "_ply.csv", options, &summary);
    else
      summary.hard_ply_stop = "not started: the barrier leg did not reach turns = " + std::to_string(options.hard_from);
  }
  return summary;
}

namespace {

// Follows `problem` in `parameter` from x (at its current value) to `target`, with progress on
// stderr; returns the end point. No measures are taken on the way (only the end matters) unless
// `events` watch them (a hard ply's complementarity): an event stops the move as a failure.
ContinuationPoint move_ply(ShootingProblem& problem, const std::string& parameter, const Eigen::VectorXd& x,
                           double target, double slenderness, const PlectonemeRunOptions& options,
                           const std::vector<ContinuationEvent>& events = {}) {
  RodContinuationOptions o = ply_continuation(problem, parameter, target, slenderness, options);
  o.samples = 11;
  // A chord iteration on an older point's matrix can throw the slenderness far off: from the
  // L/2R = 200 exact ply at 5 turns towards 500, one corrector iterate at 325.6 went to -222, where
  // no rod exists (the self-contact radius L/(2 L/2R) < 0) and the run stopped with "self-contact
  // radius must be > 0". Each point's own matrix keeps the correctors near the branch (the same
  // move reaches 500 in 22 points); the move is short next to the legs.
  if (parameter == "slenderness") o.reuse_jacobian_iterations = -1;
  if (!events.empty()) {
    o.events = events;
    o.derived = kHardMeasured;
    o.samples = 10 * static_cast<int>(slenderness) + 1;  // as on the legs: R/10 apart at the target
  }
  int points = 0;
  auto progress = [&](const ContinuationPoint& p) {
    if (options.progress_every > 0 && ++points % options.progress_every == 0)
      progress_line(options, "  ", parameter, " = ", std::setprecision(6), p.parameter);
  };
  const ContinuationResult r = RodContinuation(problem, o).run(x, progress);
  if (r.reason != StopReason::ReachedTarget || r.points.empty())
    throw std::runtime_error("the ply did not reach " + parameter + " = " + std::to_string(target) + ": " +
                             stop_text(r));
  problem.set_parameter(parameter, target);
  return r.points.back();
}

}  // namespace

PlectonemeBranchSummary follow_from_ply(const std::string& case_path, const std::string& base_state_path,
                                        double base_slenderness, double slenderness, double turns_min,
                                        double turns_max, const std::string& csv_path,
                                        const PlectonemeRunOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  PlectonemeBranchSummary summary;
  const std::string start_path = csv_path + ".start.json";
  if (both_legs_complete(csv_path, options)) {
    summary.stop = "already complete";
    return summary;
  }
  // The unknowns are those of the base run: its segments (L/2R / 5 of the base slenderness).
  const Case c = load_case(case_path, {{"slenderness", base_slenderness}});
  ShootingProblem problem(barrier_definition(c.definition, slenderness, options));
  RunState start;
  if (options.resume && std::filesystem::exists(start_path)) {
    start = load_state(start_path);
  } else {
    const RunState base = load_state(base_state_path);
    if (base.parameter_name != "turns")
      throw std::runtime_error(base_state_path + ": not the end of a plectoneme branch followed in turns");
    problem.set_parameter("turns", base.last.parameter);
    progress_line(options, "  from the L/2R = ", base_slenderness, " ply at turns = ", base.last.parameter);
    ContinuationPoint p = move_ply(problem, "slenderness", base.last.x, slenderness, slenderness, options);
    p = move_ply(problem, "log_softness", p.x, options.ply_log_softness, slenderness, options);
    start.parameter_name = "turns";
    start.last = p;
    start.last.parameter = base.last.parameter;
    start.last.jacobian.reset();
    save_state(start_path, start);
  }
  problem.set_parameter("slenderness", slenderness);
  problem.set_parameter("log_softness", options.ply_log_softness);
  problem.set_parameter("turns", start.last.parameter);
  BranchCsv csv(csv_path, c.definition.parameters.get("EI"), slenderness, options, &summary);
  csv.follow_hard_contact(csv_path, problem);
  summary.stop = follow_up_and_down(
      problem, csv, start.last, turns_min, turns_max,
      [&](double target) { return continuation_options(problem, c, slenderness, target, options); },
      &summary.refused_steps);
  summary.seconds = seconds_since(started);
  return summary;
}

PlectonemeBranchSummary follow_hard_from_ply(const std::string& case_path, const std::string& base_start_path,
                                             double base_slenderness, double slenderness, double turns_min,
                                             double turns_max, const std::string& hard_csv,
                                             const PlectonemeRunOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  PlectonemeBranchSummary summary;
  summary.stop = "exact contact only, from the L/2R = " + std::to_string(static_cast<int>(base_slenderness)) +
                 " exact ply";
  if (both_legs_complete(hard_csv, options)) {
    summary.hard_ply_stop = "already complete";
    return summary;
  }
  const Case c = load_case(case_path, {{"slenderness", slenderness}});
  const std::string start_path = hard_csv + ".start.json";
  RunState start;
  if (options.resume && std::filesystem::exists(start_path)) {
    start = load_state(start_path);
  } else {
    if (!std::filesystem::exists(base_start_path))
      throw std::runtime_error(base_start_path + ": no exact ply of L/2R = " + std::to_string(base_slenderness) +
                               " to start from (--hard-from on the slenderness before)");
    const RunState base = load_state(base_start_path);
    const Case thicker = load_case(case_path, {{"slenderness", base_slenderness}});
    // The thicker rod's segments, moving with R: coarser per R on the way, re-segmented at the end.
    ShootingProblem moving = hard_ply_problem(thicker, slenderness, base);
    moving.set_parameter("turns", base.last.parameter);
    progress_line(options, "  from the L/2R = ", base_slenderness, " exact ply at turns = ", base.last.parameter);
    const ContinuationPoint p =
        move_ply(moving, "slenderness", base.last.x, slenderness, slenderness, options, complementarity_events());
    // (The re-segmented problem takes its parameters from `moving` at p.)
    start = solved_start(resegmented_hard_ply(c.definition, moving, p.x), slenderness, base.last.parameter,
                         "the exact ply re-segmented at L/2R = " + std::to_string(slenderness));
    save_state(start_path, start);
  }
  follow_hard_legs(c, slenderness, start, turns_min, turns_max, hard_csv, options, &summary);
  summary.hard_ply_seconds = seconds_since(started);
  return summary;
}

namespace {

// Whether slenderness k of the sweep is reached from the ply of the one before it (--from-ply).
bool reached_from_ply(const PlectonemesArguments& args, size_t k) {
  return std::count(args.from_ply.begin(), args.from_ply.end(), args.slenderness[k]) > 0;
}

// Whether branch k ends with an exact ply (--hard-from below its turns, or reached from one).
bool has_exact_ply(const PlectonemesArguments& args, size_t k) {
  if (!(args.hard_from > 0.0)) return false;
  return reached_from_ply(args, k) && k > 0 ? has_exact_ply(args, k - 1) : args.hard_from < args.turns[k];
}

// Why `args` cannot make a sweep (checked before anything runs), or "".
std::string plectonemes_input_error(const PlectonemesArguments& args) {
  if (args.slenderness.size() != args.turns.size()) return "--slenderness and --turns need the same number of values";
  for (size_t k = 0; k < args.slenderness.size(); ++k)
    if (!(args.slenderness[k] > 0 && args.slenderness[k] <= 1e9) || !std::isfinite(args.turns[k]))
      return "--slenderness must be > 0 and --turns finite (value " + std::to_string(k + 1) + ")";
  if (!(args.hard_from >= 0 && std::isfinite(args.hard_from)))
    return "hard_from must be >= 0 (got " + std::to_string(args.hard_from) + ")";
  if (!(args.sensitivity_tol >= 0 && args.sensitivity_tol < 1))
    return "sensitivity_tol must be in [0, 1) (0: the state's tolerance)";
  for (size_t k = 0; k < args.slenderness.size(); ++k) {
    if (!reached_from_ply(args, k)) continue;
    const double sl = args.slenderness[k];
    std::ostringstream e;
    if (k == 0 || !(args.slenderness[k - 1] < sl)) {
      e << "L/2R = " << sl << " is reached from the ply of the slenderness before it in --slenderness, "
        << "which must be smaller";
      return e.str();
    }
    if (args.hard_from > 0.0 && !has_exact_ply(args, k - 1)) {
      e << "L/2R = " << sl << " is reached from the exact ply of L/2R = " << args.slenderness[k - 1]
        << ", which has none: --hard-from " << args.hard_from << " must be below its --turns " << args.turns[k - 1];
      return e.str();
    }
  }
  return "";
}

}  // namespace

PlectonemeSweep sweep_plectonemes(const PlectonemesArguments& args, std::ostream& report) {
  if (const std::string e = plectonemes_input_error(args); !e.empty()) throw CaseError(e);
  (void)load_case(args.case_path, {});  // a case file that cannot be used: refused before anything runs
  std::filesystem::create_directories(args.out_dir);
  const auto started = std::chrono::steady_clock::now();
  const auto csv_of = [&](double sl) {
    return args.out_dir + "/plectoneme_" + std::to_string(static_cast<int>(sl)) + ".csv";
  };
  const auto ply_csv_of = [&](double sl) { return csv_of(sl).substr(0, csv_of(sl).size() - 4) + "_ply.csv"; };
  PlectonemeSweep sweep;
  for (size_t k = 0; k < args.slenderness.size(); ++k) {
    const double sl = args.slenderness[k];
    const bool via_ply = reached_from_ply(args, k);
    const std::string csv = csv_of(sl);
    const bool exact_only = via_ply && args.hard_from > 0.0;
    if (exact_only)
      progress_line(args, "L/2R = ", sl, ": from the L/2R = ", args.slenderness[k - 1], " exact ply, then turns up to ",
                    args.turns[k], " and down to ", args.turns_min);
    else if (via_ply)
      progress_line(args, "L/2R = ", sl, ": from the L/2R = ", args.slenderness[k - 1], " ply, then turns up to ",
                    args.turns[k], " and down to ", args.turns_min);
    else
      progress_line(args, "L/2R = ", sl, ": turns 0 -> ", args.turns[k]);
    PlectonemeRunOptions options = args;  // every branch's options are the sweep's
    options.hard_turns_min = args.turns_min;
    PlectonemeSweepBranch branch;
    branch.slenderness = sl;
    try {
      branch.summary =
          exact_only ? follow_hard_from_ply(args.case_path, ply_csv_of(args.slenderness[k - 1]) + ".start.json",
                                            args.slenderness[k - 1], sl, args.turns_min, args.turns[k], ply_csv_of(sl),
                                            options)
          : via_ply  ? follow_from_ply(args.case_path, csv_of(args.slenderness[k - 1]) + ".state.json",
                                       args.slenderness[k - 1], sl, args.turns_min, args.turns[k], csv, options)
                     : follow_plectoneme_branch(args.case_path, sl, args.turns[k], csv, options);
    } catch (const std::exception& e) {
      std::ostringstream what;
      what << "L/2R = " << sl << ": " << e.what();
      throw std::runtime_error(what.str());
    }
    const PlectonemeBranchSummary& s = branch.summary;
    if (!exact_only) branch.barrier_csv = csv;
    if (!s.hard_ply_stop.empty()) branch.ply_csv = ply_csv_of(sl);
    sweep.points += s.points + s.hard_ply_points;
    report << "L/2R = " << sl << ": ";
    if (exact_only)
      report << "no barrier branch";
    else
      report << s.points << " points in " << std::setprecision(3) << s.seconds << " s";
    if (s.points > 0) report << " (" << s.points / s.seconds << " points/s)";
    report << std::setprecision(6) << ", " << s.refused_steps << " steps refused (through itself)";
    if (s.hard_points > 0)
      report << ", " << s.hard_points << " points re-solved with hard contact (" << s.hard_failures << " failed) in "
             << std::setprecision(3) << s.hard_seconds << " s" << std::setprecision(6);
    if (!s.hard_ply_stop.empty())
      report << "; the ply with exact contact: " << s.hard_ply_points << " points in " << std::setprecision(3)
             << s.hard_ply_seconds << " s" << std::setprecision(6) << ", stopped: " << s.hard_ply_stop;
    // Flushed: a sweep killed later keeps the lines of the branches it finished.
    report << ", stopped: " << s.stop << ", " << (exact_only ? ply_csv_of(sl) : csv) << std::endl;
    sweep.branches.push_back(std::move(branch));
  }
  sweep.seconds = seconds_since(started);
  return sweep;
}

}  // namespace kirchhoff
