#include "continue_command.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "kirchhoff/case_file.hpp"
#include "kirchhoff/contact.hpp"
#include "kirchhoff/continuation.hpp"
#include "kirchhoff/self_passage.hpp"
#include "kirchhoff/discrete_seed.hpp"
#include "kirchhoff/solution.hpp"
#include "run_state.hpp"
#include "solve_command.hpp"

namespace kirchhoff::cli {
namespace {

namespace fs = std::filesystem;

// Branch points already written on branch 0 (for resuming a run with --switch-at-bp).
int count_branch_points(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  int count = 0;
  while (std::getline(in, line))
    if (line.find(",0,") == line.find(',') && line.find(",branch_point,") != std::string::npos) ++count;
  return count;
}

// Rows already written on a branch (max_points counts a branch's points across resumes).
int count_rows_on_branch(const fs::path& path, int branch) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  const std::string tag = "," + std::to_string(branch) + ",";
  int count = 0;
  while (std::getline(in, line))
    if (line.find(tag) == line.find(',')) ++count;
  return count;
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
      out_ << ",H_spread,m3_spread,n_dot_m_spread,H_flat,type,multiplicity,event,newton_iterations\n";
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
         << p.newton_iterations << '\n';
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

}  // namespace

int run_continue(const ContinueArguments& args) {
  Case c;
  ContinuationOptions options;
  Eigen::VectorXd start_point;  // --start-from: the unknowns to start from
  try {
    ParameterOverrides overrides;
    for (const auto& t : args.overrides) overrides.push_back(parse_override(t));
    c = load_case(args.case_path, overrides, args.phase_condition);
    options.parameter = args.parameter;
    if (!c.definition.parameters.contains(args.parameter))
      throw CaseError(args.case_path + ": --param " + args.parameter + ": not a parameter of the case");
    if (args.has_to) options.target = args.to;
    options.initial_step = args.step;
    options.min_step = args.min_step;
    options.max_step = args.max_step;
    options.max_points = args.max_points;
    options.samples = args.samples;
    options.detect_branch_points = !args.no_branch_points;
    if (args.no_branch_points && args.switch_at_bp > 0)
      throw CaseError("--switch-at-bp needs branch points: drop --no-branch-points");
    options.derived = c.derived;
    options.events = parse_events(args.stop_events, true);
    for (auto& e : parse_events(args.record_events, false)) options.events.push_back(e);
    if (std::string e = options.validate(); !e.empty()) throw CaseError(e);
    if (!args.start_from.empty()) {
      if (args.resume || args.seed.ipopt) throw CaseError("--start-from does not combine with --resume or --seed");
      if (!c.definition.obstacles.empty())
        throw CaseError("--start-from is not implemented for cases with obstacles (their active set)");
      const RunState from = load_state(args.start_from);
      const std::string name = from.parameter_name.empty() ? args.start_param : from.parameter_name;
      if (name.empty())
        throw CaseError(args.start_from + " does not name its parameter: give it with --start-param");
      if (!c.definition.parameters.contains(name))
        throw CaseError(args.start_from + ": its parameter '" + name + "' is not a parameter of the case");
      if (name != args.parameter) c.definition.parameters.set(name, from.last.parameter);
      start_point = from.last.x;
      std::cerr << "start: the point at " << name << " = " << std::setprecision(15) << from.last.parameter << " of "
                << args.start_from << "\n" << std::setprecision(6);
    }
    if (args.seed.ipopt && !args.resume) {
      // The first point from Ipopt's shape and contact set instead of the case's guess.
      const DiscreteSeed seed = seed_from_discrete_energy(c.definition, args.seed.segments, args.seed.amplitude);
      std::cerr << "seed: " << seed.summary << "\n";
      c.definition.contacts = seed.contacts;
      c.start_guess = seed.start;
    }
  } catch (const CaseError& e) {
    std::cerr << "error: " << e.what() << "\n";
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

  if (!c.definition.obstacles.empty() && args.switch_at_bp > 0) {
    std::cerr << "error: " << args.case_path << ": --switch-at-bp is not implemented for cases with obstacles yet\n";
    return kExitBadInput;
  }
  const fs::path csv(args.out_path), state_path(args.out_path + ".state.json");
  if (!args.profiles_dir.empty()) fs::create_directories(args.profiles_dir);
  Progress progress(args.parameter);
  RunState state;
  state.phase_condition = args.phase_condition.empty() ? "none" : args.phase_condition;
  std::unique_ptr<BranchWriter> writer;

  try {
    if (args.resume) {
      state = load_state(state_path);
      truncate_csv(csv, state.row);
    }
    state.parameter_name = args.parameter;
    std::vector<std::string> columns = c.definition.unknown_parameters;  // solved-for parameters first
    columns.insert(columns.end(), options.derived.begin(), options.derived.end());
    writer = std::make_unique<BranchWriter>(csv, args.parameter, columns, args.resume);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }

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
                      s.profile);
  };

  auto sink_for = [&](const ShootingProblem& problem, int branch, const std::string& phase) {
    return [&, branch, phase](const ContinuationPoint& p) {
      ++state.row;
      writer->write(state.row, p, branch);
      // Only points the march goes on from are resumable: a run killed after a special point
      // (fold, branch point, event) redoes the step that found it, and its row is rewritten.
      if (resumable(p)) {
        state.branch = branch;
        state.phase_condition = phase;
        save_resume_point(state_path, p, &state);
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
      std::vector<PointContact> active;
      std::unique_ptr<ShootingProblem> leg_problem;  // for --profiles
      auto sink = [&](const ContinuationPoint& p) {
        ++state.row;
        writer->write(state.row, p, 0);
        if (resumable(p)) {
          state.contacts = active;
          save_resume_point(state_path, p, &state);
        }
        progress.point(state.row, p, 0);
        if (leg_problem) write_profile(*leg_problem, p);
      };
      auto on_active_set = [&](const std::vector<PointContact>& contacts) {
        active = contacts;
        if (args.profiles_dir.empty()) return;
        // The points that follow belong to this leg's problem (its active set).
        ProblemDefinition d = c.definition;
        d.contacts = contacts;
        leg_problem = std::make_unique<ShootingProblem>(d);
      };
      ContactContinuationResult r;
      if (args.resume) {
        ProblemDefinition d = c.definition;
        d.contacts = state.contacts;
        ContinuationOptions rest = options;
        // The resumed march counts its start point, which is already written.
        rest.max_points = std::max(1, options.max_points - count_rows_on_branch(csv, 0) + 1);
        active = state.contacts;
        r = resume_with_contacts(d, state.last, rest, sink, {}, on_active_set);
      } else {
        r = continue_with_contacts(c.definition, c.start_guess, options, sink, {}, on_active_set);
      }
      progress.done();
      for (const auto& line : r.changes) std::cerr << "contact: " << line << "\n";
      std::cerr << "stopped: " << to_string(r.result.reason)
                << (r.result.message.empty() ? "" : " (" + r.result.message + ")") << "; " << state.row + 1
                << " points in " << args.out_path << "\n";
      const bool failed = r.result.reason == StopReason::StartFailed || r.result.reason == StopReason::StepTooSmall ||
                          r.result.reason == StopReason::Inadmissible;
      return failed ? kExitNotConverged : kExitOk;
    } catch (const std::exception& e) {
      progress.done();
      std::cerr << "error: " << e.what() << "\n";
      return kExitNotConverged;
    }
  }
  try {
    auto problem = problem_for(state.phase_condition);
    if (start_point.size() > 0 && start_point.size() != problem->size()) {
      progress.done();
      std::cerr << "error: " << args.start_from << ": its point has " << start_point.size() << " unknowns, the case "
                << problem->size() << " (set the parameters that fix the segments as in that run)\n";
      return kExitBadInput;
    }
    ContinuationOptions first = options;
    // A rod with self-contact: steps that would carry it through itself are refused.
    if (guard_self_passage(*problem, &first)) std::cerr << "self-contact: steps through the rod itself are refused\n";
    if (branch == 0 && args.switch_at_bp > 0)
      first.stop_at_branch_point = args.switch_at_bp - (args.resume ? count_branch_points(csv) : 0);
    if (args.resume) {
      problem->set_parameter(args.parameter, state.last.parameter);
      // The resumed march counts its start point, which is already written.
      first.max_points = std::max(1, options.max_points - count_rows_on_branch(csv, branch) + 1);
    }
    Continuation run(*problem, first);
    // (A resume never starts on a branch point: only points the march goes on from are saved.)
    result = args.resume ? run.resume(state.last, sink_for(*problem, branch, state.phase_condition))
                         : run.run(start_point.size() > 0 ? start_point : problem->initial_unknowns(c.start_guess),
                                   sink_for(*problem, 0, state.phase_condition));
    if (branch == 0 && args.switch_at_bp > 0) {
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
  std::cerr << "stopped: " << to_string(result.reason) << (result.message.empty() ? "" : " (" + result.message + ")")
            << "; " << state.row + 1 << " points (last on branch " << branch << ") in " << args.out_path << "\n";
  if (result.refused_steps > 0) std::cerr << result.refused_steps << " steps refused and retried shorter\n";
  const bool ok = result.reason != StopReason::StartFailed && result.reason != StopReason::StepTooSmall &&
                  result.reason != StopReason::Inadmissible;
  return ok ? kExitOk : kExitNotConverged;
}

}  // namespace kirchhoff::cli
