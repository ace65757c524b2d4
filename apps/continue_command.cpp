#include "continue_command.hpp"

#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "kirchhoff/case_file.hpp"
#include "kirchhoff/contact.hpp"
#include "kirchhoff/deflated_continuation.hpp"
#include "kirchhoff/continuation.hpp"
#include "kirchhoff/self_passage.hpp"
#include "kirchhoff/discrete_seed.hpp"
#include "kirchhoff/solution.hpp"
#include "run_state.hpp"
#include "solve_command.hpp"

namespace kirchhoff::cli {
namespace {

namespace fs = std::filesystem;

// Data rows of a branch CSV (0 when there is none).
int data_rows(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // the header
  int count = 0;
  while (std::getline(in, line))
    if (!line.empty()) ++count;
  return count;
}

// The arguments that decide a run's points, in one line: a state file records them, and a
// resume with other ones is refused (it would not continue the same run). The output paths and
// --resume itself are not among them.
// The case is named by its canonical path and its content's FNV-1a hash (an edited case file is
// another run too).
std::string run_arguments(const ContinueArguments& a) {
  std::ifstream in(a.case_path, std::ios::binary);
  std::uint64_t hash = 14695981039346656037ull;
  for (char ch; in.get(ch);) hash = (hash ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(a.case_path, ec);
  std::ostringstream o;
  o << std::setprecision(17) << "case=" << (ec ? fs::path(a.case_path) : canonical).string() << " case_hash=" << std::hex
    << hash << std::dec << " param=" << a.parameter;
  for (const auto& s : a.overrides) o << " set=" << s;
  for (const auto& s : a.solver) o << " solver=" << s;  // none: the line older state files hold
  o << " phase=" << a.phase_condition << " to=";
  if (a.has_to)
    o << a.to;
  else
    o << "none";
  o << " step=" << a.step
    << " min_step=" << a.min_step << " max_step=" << a.max_step << " max_points=" << a.max_points
    << " switch_at_bp=" << a.switch_at_bp << " side=" << a.switch_side << " branch_points=" << !a.no_branch_points << " stability=" << !a.no_stability;
  for (const auto& e : a.stop_events) o << " event=" << e;
  for (const auto& e : a.record_events) o << " record=" << e;
  // (Only when given, so that the line of a run without it is the one older state files hold.)
  if (!a.start_from.empty()) o << " start_from=" << fs::weakly_canonical(a.start_from, ec).string();
  o << " samples=" << a.samples << " seed=" << (a.seed.ipopt ? "ipopt" : "guess");
  if (a.seed.ipopt) o << " seed_segments=" << a.seed.segments << " seed_amplitude=" << a.seed.amplitude;
  return o.str();
}

// For tests and tests/resume_soak.sh: KIRCHHOFF_TEST_KILL_AFTER_ROW=K makes the run kill itself
// with SIGKILL right after row K is written and flushed, before the state is saved for it (the
// narrowest window a real kill can hit: the row is on disk, the state is the previous point's);
// -1 kills it once the CSV header is written, before any point. Nothing is cleaned up, as with a
// real kill. Unset (or not a number), runs are not affected.
int kill_after_row() {
  const char* value = std::getenv("KIRCHHOFF_TEST_KILL_AFTER_ROW");
  if (!value || !*value) return -2;
  char* end = nullptr;
  const long k = std::strtol(value, &end, 10);
  return *end == '\0' && k >= -1 ? static_cast<int>(k) : -2;
}

class BranchWriter {
 public:
  BranchWriter(const fs::path& path, const std::string& parameter, std::vector<std::string> derived, bool append)
      : derived_(std::move(derived)) {
    out_.open(path, append ? std::ios::app : std::ios::trunc);
    if (!out_) throw std::runtime_error("cannot write " + path.string());
    out_ << std::setprecision(15);
    if (!append) {
      out_ << "index,branch," << parameter << ",arclength";
      for (const auto& d : derived_) out_ << ',' << d;
      out_ << ",H_spread,m3_spread,n_dot_m_spread,H_flat,type,multiplicity,event,newton_iterations,stability_index,"
              "zero_modes\n";
      out_.flush();
    }
  }
  void write(int row, const ContinuationPoint& p, int branch) {
    out_ << row << ',' << branch << ',' << p.parameter << ',' << p.arclength;
    for (const auto& d : derived_) out_ << ',' << (p.derived.count(d) ? p.derived.at(d) : NAN);
    const auto& inv = p.invariants;
    // + 0.0 prints a zero spread as 0, not -0.
    out_ << ',' << inv.H.relative_spread() + 0.0 << ',' << inv.m3.relative_spread() + 0.0 << ','
         << inv.n_dot_m.relative_spread() + 0.0
         << ',' << (p.H_flat ? 1 : 0) << ',' << to_string(p.type) << ',' << p.multiplicity << ',' << p.event << ','
         << p.newton_iterations << ',';
    // Empty where the index is not defined (or not computed): never a guessed number.
    if (p.stability_index) out_ << *p.stability_index;
    out_ << ',' << p.zero_modes << '\n';
    out_.flush();
  }

 private:
  std::ofstream out_;
  std::vector<std::string> derived_;
};

// One line updated in place on a terminal, plain lines (every 10th point and every special
// point) otherwise.
class Progress {
 public:
  explicit Progress(std::string parameter) : parameter_(std::move(parameter)), tty_(isatty(STDERR_FILENO)) {}
  void point(int row, const ContinuationPoint& p, int branch) {
    std::ostringstream line;
    line << "branch " << branch << "  point " << row << "  " << parameter_ << " = " << std::setprecision(10)
         << p.parameter << "  step " << std::setprecision(3) << p.step;
    if (p.type != PointType::Regular && p.type != PointType::Start) line << "  [" << to_string(p.type) << "]";
    if (!p.H_flat) line << "  [H not flat]";
    if (p.stability_index) line << (*p.stability_index == 0 ? "  stable" : "  index " + std::to_string(*p.stability_index));
    if (tty_) {
      std::cerr << "\r" << line.str() << "\033[K" << std::flush;
    } else if (row % 10 == 0 || p.type != PointType::Regular || !p.H_flat) {
      std::cerr << line.str() << "\n";
    }
  }
  void done() {
    if (tty_) std::cerr << "\n";
  }

 private:
  std::string parameter_;
  bool tty_;
};

std::vector<ContinuationEvent> parse_events(const std::vector<std::string>& texts, bool stop) {
  std::vector<ContinuationEvent> out;
  for (const auto& t : texts) {
    const auto [name, value] = parse_override(t);
    if (!derived_catalogue().count(name)) throw CaseError("--event/--record: '" + name + "' is not a derived quantity");
    out.push_back({name, value, stop, ""});
  }
  return out;
}

// A run started from another case's run: the names its state brings that this case lacks, said
// as such (load_case would call them a --set the user never typed).
void refuse_foreign_parameters(const RunStart& start, const ContinueArguments& args) {
  const Case plain = load_case(args.case_path, {}, args.phase_condition);
  for (size_t k = 0; k < start.parameters.size(); ++k)
    if (!plain.file_parameters.contains(start.parameters[k].first))
      throw CaseError(args.start_from + ": its run's parameter '" + start.parameters[k].first + "' (" +
                      start.sources[k] + ") is not a parameter of " + args.case_path);
}

// The parameter values a run started from another one starts with: each that differs from the
// case file's or was given (whence it comes), and the continued one.
void print_start(const RunStart& start, const Case& c, const std::string& parameter) {
  std::cerr << std::setprecision(15) << "start: from row " << start.at.row << " (" << to_string(start.at.point.type)
            << ") of the run in " << start.from_parameter;
  if (!start.at.contacts.empty()) std::cerr << ", " << start.at.contacts.size() << " active contact(s)";
  std::cerr << "; parameters other than the case file's:\n";
  const Parameters& now = c.definition.parameters;
  for (int k = 0; k < now.size(); ++k) {
    const std::string& name = now.names()[static_cast<size_t>(k)];
    const auto given = std::find_if(start.parameters.begin(), start.parameters.end(),
                                    [&](const auto& p) { return p.first == name; });
    const bool differs = !c.file_parameters.contains(name) || c.file_parameters.get(name) != now.values()[k];
    if (given == start.parameters.end() && !differs) continue;
    std::cerr << "  " << name << " = " << now.values()[k];
    if (given != start.parameters.end())
      std::cerr << "  (" << start.sources[static_cast<size_t>(given - start.parameters.begin())] << ")";
    else
      std::cerr << "  (computed from the others)";
    std::cerr << "\n";
  }
  std::cerr << "continuing in " << parameter << " from " << now.get(parameter) << "\n" << std::setprecision(6);
  for (const auto& note : start.notes) std::cerr << "note: " << note << "\n";
}

// --deflate: the equilibria at the start, then the branch through each, written as branches
// 0, 1, ... of the CSV (no state file: such a run is not resumable).
int continue_deflated(const ContinueArguments& args, const Case& c, const ContinuationOptions& options,
                      BranchWriter& writer, Progress& progress) {
  EquilibriaOptions search;
  search.max_equilibria = args.deflate_max;
  search.max_seconds = args.max_seconds;
  int row = -1;
  const auto sink_for = [&](int rank, const Equilibrium& start) -> PointSink {
    progress.done();
    std::cerr << "branch " << rank << ": from the equilibrium of energy " << start.energy << " ("
              << describe(start.stability) << ", found by " << start.found_by << ")\n";
    return [&, rank](const ContinuationPoint& p) {
      writer.write(++row, p, rank);
      progress.point(row, p, rank);
    };
  };
  EveryBranch all;
  try {
    all = continue_every_branch(c.definition, c.start_guess, c.derived, c.samples, options, search, sink_for);
  } catch (const std::exception& e) {
    progress.done();
    std::cerr << "error: " << e.what() << "\n";
    return kExitNotConverged;
  }
  progress.done();
  std::cerr << all.search.equilibria.size() << " equilibria at the start (" << all.search.stopped_because << ")\n";
  bool ok = !all.branches.empty();
  for (const auto& b : all.branches) {
    std::cerr << "branch " << b.rank << " stopped: " << to_string(b.result.reason)
              << (b.result.message.empty() ? "" : " (" + b.result.message + ")") << "\n";
    for (const auto& line : b.contact_changes) std::cerr << "  contact: " << line << "\n";
    ok = ok && b.result.reason != StopReason::StartFailed && b.result.reason != StopReason::StepTooSmall &&
         b.result.reason != StopReason::Inadmissible && b.result.reason != StopReason::TimeLimit;
  }
  std::cerr << row + 1 << " points on " << all.branches.size() << " branches in " << args.out_path << "\n";
  return ok ? kExitOk : kExitNotConverged;
}

}  // namespace

int run_continue(const ContinueArguments& args) {
  Case c;
  ContinuationOptions options;
  Eigen::VectorXd start_point;  // --start-from: the unknowns to start from
  const fs::path csv(args.out_path), state_path(args.out_path + ".state.json");
  // A run killed before it saved its first point (its start) has no state file, and at most the
  // start's row, which it had not finished: resuming it is starting it again, which rewrites the
  // CSV with the same rows. More rows and no state means the state was removed or the rows are
  // another run's: nothing records where that march stood, so it is refused.
  if (args.deflate && (args.resume || !args.start_from.empty() || args.switch_at_bp > 0 || args.seed.ipopt)) {
    std::cerr << "error: --deflate starts every branch from the equilibria it finds: it does not combine with "
                 "--resume, --start-from, --switch-at-bp or --seed (a --deflate run is not resumable)\n";
    return kExitBadInput;
  }
  bool resuming = args.resume;
  if (args.resume && !fs::exists(state_path)) {
    if (const int rows = data_rows(csv); rows > 1) {
      std::cerr << "error: cannot resume: " << csv.string() << " has " << rows << " rows but there is no state file "
                << state_path.string() << " (a run saves it after its first point, so it was removed or the rows "
                << "come from another run); run again without --resume to compute the branch from its start\n";
      return kExitBadInput;
    }
    std::cerr << "resume: no state file " << state_path.string()
              << ": the run was stopped before its first point was saved, so it starts from the beginning\n";
    resuming = false;
  }
  std::optional<RunState> saved;  // --resume: the interrupted run's state
  std::optional<RunStart> start;  // --start-from: where and with which parameters the run starts
  ParameterOverrides overrides;   // the run's parameter values beyond the case file's
  try {
    for (const auto& t : args.overrides) overrides.push_back(parse_override(t));
    if (resuming) {
      saved = load_state(state_path);
      // A run started from another one keeps the values it started with (the other run's, which
      // its arguments line does not hold).
      if (saved->has_set_parameters) overrides = saved->set_parameters;
    } else if (!args.start_from.empty()) {
      if (args.seed.ipopt) throw CaseError("--start-from does not combine with --seed");
      start = plan_start_from(args.start_from, args.start_param, overrides);
      overrides = start->parameters;
      refuse_foreign_parameters(*start, args);
    }
    c = load_case(args.case_path, overrides, args.phase_condition, parse_solver_overrides(args.solver));
    options.parameter = args.parameter;
    if (!c.definition.parameters.contains(args.parameter))
      throw CaseError(args.case_path + ": --param " + args.parameter + ": not a parameter of the case");
    if (const std::string why = dependent_parameter_refusal(c.definition.dependent_parameters, args.parameter,
                                                            "continue in");
        !why.empty())
      throw CaseError(args.case_path + ": --param " + args.parameter + ": " + why);
    if (args.has_to) options.target = args.to;
    options.initial_step = args.step;
    options.min_step = args.min_step;
    options.max_step = args.max_step;
    options.max_points = args.max_points;
    options.samples = args.samples;
    if (!(args.max_seconds >= 0 && args.max_seconds <= 1e9)) throw CaseError("--max-seconds must be in [0, 1e9]");
    if (args.max_seconds > 0) {
      // One deadline for the whole run: the first solve, every branch and every contact leg.
      limit_wall_clock(c.definition.options, args.max_seconds);
      options.deadline = c.definition.options.newton.deadline;
    }
    options.detect_branch_points = !args.no_branch_points;
    options.compute_stability = !args.no_stability;
    if (args.no_branch_points && args.switch_at_bp > 0)
      throw CaseError("--switch-at-bp needs branch points: drop --no-branch-points");
    options.derived = c.derived;
    options.events = parse_events(args.stop_events, true);
    for (auto& e : parse_events(args.record_events, false)) options.events.push_back(e);
    if (std::string e = options.validate(); !e.empty()) throw CaseError(e);
    if (start) {
      if (!start->at.contacts.empty() && c.definition.obstacles.empty())
        throw CaseError(args.start_from + ": its point has active contacts, and " + args.case_path +
                        " has no obstacles");
      c.definition.contacts = start->at.contacts;  // the active set the point's unknowns belong to
      start_point = start->at.point.x;
      print_start(*start, c, args.parameter);
      // The point's unknowns are those of the case with its active set (and the phase condition
      // of a branch switched onto at a double branch point).
      ProblemDefinition d = c.definition;
      if (start->at.phase_condition == "axial" && !d.parameters.contains("unfolding")) add_axial_phase_condition(d);
      if (const auto n = ShootingProblem(d).size(); start_point.size() != n)
        throw CaseError(args.start_from + ": its point has " + std::to_string(start_point.size()) +
                        " unknowns, the case " + std::to_string(n) +
                        " (set the parameters that fix the segments as in that run)");
    }
    if (args.seed.ipopt && !resuming) {
      // The first point from Ipopt's shape and contact set instead of the case's guess.
      const DiscreteSeed seed = seed_from_discrete_energy(c.definition, args.seed.segments, args.seed.amplitude);
      std::cerr << "seed: " << seed.summary << "\n";
      c.definition.contacts = seed.contacts;
      c.start_guess = seed.start;
    }
  } catch (const CaseError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const nlohmann::json::exception& e) {  // a state file that is not one
    std::cerr << "error: " << state_path.string() << ": not a state file of this command: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::runtime_error& e) {  // the seed's Ipopt did not converge
    std::cerr << "error: " << e.what() << "\n";
    return kExitNotConverged;
  }
  for (const auto& e : options.events)
    if (std::find(options.derived.begin(), options.derived.end(), e.quantity) == options.derived.end())
      options.derived.push_back(e.quantity);

  if (!args.profiles_dir.empty()) fs::create_directories(args.profiles_dir);
  Progress progress(args.parameter);
  RunState state;
  state.phase_condition = args.phase_condition.empty() ? "none" : args.phase_condition;
  // A point on a branch followed with the axial phase condition goes on in that problem.
  if (start && start->at.phase_condition == "axial") state.phase_condition = "axial";
  state.arguments = run_arguments(args);
  std::unique_ptr<BranchWriter> writer;
  const int kill_after = kill_after_row();

  try {
    if (resuming) {
      // Without the march's whole state (files written before 2026-12-02) or with other
      // arguments, the resumed run would not be the interrupted one continued: refused, not
      // approximated.
      if (!saved->has_march)
        throw CaseError("cannot resume from " + state_path.string() +
                        ": it was written by an older kirchhoff that did not save the march's whole state, so a "
                        "resumed run would not repeat the uninterrupted one; run again without --resume");
      if (saved->arguments != state.arguments)
        throw CaseError("cannot resume from " + state_path.string() + ": it belongs to a run with other arguments\n  saved: " +
                        saved->arguments + "\n  now:   " + state.arguments);
      state = std::move(*saved);
      truncate_csv(csv, state.row);
      // The rows after the saved point are gone: the last one is the saved point's.
      state.written = WrittenPoint{state.saved_row, state.branch, state.phase_condition, state.last, state.contacts};
    }
    state.parameter_name = args.parameter;
    state.has_set_parameters = true;
    state.set_parameters = overrides;
    std::vector<std::string> columns = c.definition.unknown_parameters;  // solved-for parameters first
    columns.insert(columns.end(), options.derived.begin(), options.derived.end());
    writer = std::make_unique<BranchWriter>(csv, args.parameter, columns, resuming);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (kill_after == -1) kill(getpid(), SIGKILL);
  if (args.deflate) return continue_deflated(args, c, options, *writer, progress);

  // The problem of the current branch (the switched branch of a symmetric rod has the phase
  // condition added).
  auto problem_for = [&](const std::string& phase) {
    ProblemDefinition d = c.definition;
    if (phase == "axial" && !d.parameters.contains("unfolding")) add_axial_phase_condition(d);
    return std::make_unique<ShootingProblem>(d);
  };

  // DIR/point_NNNNN.csv for --profiles: the point's solution along the rod, in its problem.
  auto write_profile = [&](const ShootingProblem& problem, const ContinuationPoint& p) {
    if (args.profiles_dir.empty()) return;
    ShootingProblem copy = problem;
    copy.set_parameter(args.parameter, p.parameter);
    ShootingResult r;
    r.x = p.x;
    r.parameters = copy.parameters_at(p.x);
    const Solution s = make_solution(copy, r, args.samples, {});
    std::ostringstream name;
    name << "point_" << std::setw(5) << std::setfill('0') << state.row << ".csv";
    write_profile_csv((fs::path(args.profiles_dir) / name.str()).string(), copy.equations(r.parameters)->model(),
                      s.profile, copy.definition().kind);
  };

  // The state is saved after every point a run can resume from (options.on_resumable, called
  // right after the point's row is written): a run killed after a special point (fold, branch
  // point, event) redoes the step that found it from the point before, and its row is rewritten.
  auto save_march = [&](const MarchState& m) {
    set_march_state(&state, m);
    state.saved_row = state.row;
    save_state(state_path, state);
  };
  // The row just written, where a run started from this one starts (--start-from): saved now
  // unless the point is resumable (then the march's state is saved right after it).
  auto record_written = [&](const ContinuationPoint& p, int branch, const std::string& phase,
                            const std::vector<PointContact>& contacts) {
    state.written = WrittenPoint{state.row, branch, phase, p, contacts};
    state.written->point.jacobian.reset();
    if (!resumable(p) && state.has_march) save_state(state_path, state);
  };
  auto sink_for = [&](const ShootingProblem& problem, int branch, const std::string& phase) {
    return [&, branch, phase](const ContinuationPoint& p) {
      ++state.row;
      writer->write(state.row, p, branch);
      if (state.row == kill_after) kill(getpid(), SIGKILL);
      record_written(p, branch, phase, {});
      if (resumable(p)) {
        state.branch = branch;
        state.phase_condition = phase;
      }
      progress.point(state.row, p, branch);
      write_profile(problem, p);
    };
  };

  // Branch 0 runs until its target (or, with --switch-at-bp K, its K-th branch point); branch 1
  // starts on the bifurcating branch there. A resumed run picks up whichever it was on.
  ContinuationResult result;
  int branch = state.branch;
  auto switch_branches = [&](Continuation& run, const ContinuationPoint& bp) {
    branch = 1;
    return follow_bifurcating_branch(run, bp, options, args.switch_side,
                                     [&](const ShootingProblem& problem, bool with_phase_condition) {
                                       std::cerr << (isatty(STDERR_FILENO) ? "\n" : "");
                                       if (with_phase_condition)
                                         std::cerr << "double branch point at " << args.parameter << " = "
                                                   << bp.parameter << ": switching with the axial phase condition\n";
                                       else
                                         std::cerr << "switching branches at " << args.parameter << " = "
                                                   << bp.parameter << "\n";
                                       return sink_for(problem, 1,
                                                       with_phase_condition ? "axial" : state.phase_condition);
                                     });
  };
  if (!c.definition.obstacles.empty()) {
    // Contact: the active set changes along the branch (each change is an event row).
    try {
      std::unique_ptr<ShootingProblem> leg_problem;  // for --profiles
      std::vector<PointContact> leg_contacts;         // the active set of the leg's points
      auto sink = [&](const ContinuationPoint& p) {
        ++state.row;
        writer->write(state.row, p, branch);
        if (state.row == kill_after) kill(getpid(), SIGKILL);
        record_written(p, branch, state.phase_condition, leg_contacts);
        progress.point(state.row, p, branch);
        if (leg_problem) write_profile(*leg_problem, p);
      };
      // The leg's state (its active set among it) after every point the run can resume from.
      auto save_leg = [&](const ContactMarchState& m) {
        set_contact_march_state(&state, m);
        state.branch = branch;
        state.saved_row = state.row;
        save_state(state_path, state);
      };
      auto on_active_set = [&](const std::vector<PointContact>& contacts) {
        leg_contacts = contacts;
        if (args.profiles_dir.empty()) return;
        // The points that follow belong to this leg's problem (its active set).
        ProblemDefinition d = c.definition;
        d.contacts = contacts;
        leg_problem = std::make_unique<ShootingProblem>(d);
      };
      // As without obstacles: branch 0 to its target or the K-th branch point (counted over its
      // legs), branch 1 from there with no target.
      ContinuationOptions first = branch == 1 ? bifurcating_branch_options(options) : options;
      if (branch == 0) first.stop_at_branch_point = args.switch_at_bp;
      ContactContinuationResult r;
      r = resuming
              ? resume_with_contacts(c.definition, contact_march_state(state), first, sink, {}, on_active_set, save_leg)
          : start_point.size() > 0
              ? continue_with_contacts_from(c.definition, start_point, first, sink, {}, on_active_set, save_leg)
              : continue_with_contacts(c.definition, c.start_guess, first, sink, {}, on_active_set, save_leg);
      if (branch == 0 && args.switch_at_bp > 0 && r.result.reason != StopReason::TimeLimit) {
        progress.done();
        for (const auto& line : r.changes) std::cerr << "contact: " << line << "\n";
        if (r.result.reason != StopReason::BranchPointStop) {
          std::cerr << "error: no branch point " << args.switch_at_bp << " before the run stopped ("
                    << to_string(r.result.reason) << (r.result.message.empty() ? "" : ": " + r.result.message)
                    << ")\n";
          return kExitNotConverged;
        }
        const ContinuationPoint bp = r.result.points.back();
        std::cerr << "switching branches at " << args.parameter << " = " << bp.parameter << "\n";
        branch = 1;
        r = switch_branch_with_contacts(r.definition, bp, args.switch_side, options, sink, {}, on_active_set, save_leg);
      }
      progress.done();
      if (state.has_march) save_state(state_path, state);  // with the last row written
      for (const auto& line : r.changes) std::cerr << "contact: " << line << "\n";
      std::cerr << "stopped: " << to_string(r.result.reason)
                << (r.result.message.empty() ? "" : " (" + r.result.message + ")") << "; " << state.row + 1
                << " points in " << args.out_path << "\n";
      const bool failed = r.result.reason == StopReason::StartFailed || r.result.reason == StopReason::StepTooSmall ||
                          r.result.reason == StopReason::Inadmissible || r.result.reason == StopReason::TimeLimit;
      return failed ? kExitNotConverged : kExitOk;
    } catch (const std::exception& e) {
      progress.done();
      std::cerr << "error: " << e.what() << "\n";
      return kExitNotConverged;
    }
  }
  options.on_resumable = save_march;
  try {
    auto problem = problem_for(state.phase_condition);
    // Each branch's march is run with the options the uninterrupted run gives it, a resumed one
    // too: branch 0 with the target, the self-passage guard and the stop at the K-th branch
    // point (the count of those passed is in the saved state), branch 1 with
    // bifurcating_branch_options (no target: `--to` applied there stopped resumed runs at it).
    ContinuationOptions first = options;
    // A rod with self-contact: steps that would carry it through itself are refused.
    if (branch == 0 && guard_self_passage(*problem, &first))
      std::cerr << "self-contact: steps through the rod itself are refused\n";
    if (branch == 0 && args.switch_at_bp > 0) first.stop_at_branch_point = args.switch_at_bp;
    if (branch == 1) first = bifurcating_branch_options(options);
    if (resuming) problem->set_parameter(args.parameter, state.last.parameter);
    Continuation run(*problem, first);
    // (A resume never starts on a branch point: only points the march goes on from are saved.)
    result = resuming ? run.resume(march_state(state), sink_for(*problem, branch, state.phase_condition))
                      : run.run(start_point.size() > 0 ? start_point : problem->initial_unknowns(c.start_guess),
                                sink_for(*problem, 0, state.phase_condition));
    if (branch == 0 && args.switch_at_bp > 0 && result.reason != StopReason::TimeLimit) {
      if (result.reason != StopReason::BranchPointStop) {
        progress.done();
        std::cerr << "error: no branch point " << args.switch_at_bp << " before the run stopped ("
                  << to_string(result.reason) << ")\n";
        return kExitNotConverged;
      }
      result = switch_branches(run, result.points.back());
    }
  } catch (const std::exception& e) {
    progress.done();
    std::cerr << "error: " << e.what() << "\n";
    return kExitNotConverged;
  }
  progress.done();
  if (state.has_march) save_state(state_path, state);  // with the last row written
  std::cerr << "stopped: " << to_string(result.reason) << (result.message.empty() ? "" : " (" + result.message + ")")
            << "; " << state.row + 1 << " points (last on branch " << branch << ") in " << args.out_path << "\n";
  if (result.refused_steps > 0) std::cerr << result.refused_steps << " steps refused and retried shorter\n";
  if (result.reason == StopReason::TimeLimit) std::cerr << "the run can go on with --resume\n";
  const bool ok = result.reason != StopReason::StartFailed && result.reason != StopReason::StepTooSmall &&
                  result.reason != StopReason::Inadmissible && result.reason != StopReason::TimeLimit;
  return ok ? kExitOk : kExitNotConverged;
}

}  // namespace kirchhoff::cli
