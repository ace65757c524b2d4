#include "continue_command.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "kirchhoff/analysis/point_record.hpp"
#include "kirchhoff/jobs/case_continue.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/continue_outputs.hpp"
#include "kirchhoff/jobs/run_plan.hpp"
#include "kirchhoff/jobs/run_state.hpp"
#include "solve_command.hpp"

namespace kirchhoff::cli {
namespace {

namespace fs = std::filesystem;

// For tests and tests/resume_soak.sh: KIRCHHOFF_TEST_KILL_AFTER_ROW=K makes the run kill itself
// with SIGKILL right after row K is written and flushed, before the state is saved for it (the
// narrowest window a real kill can hit: the row is on disk, the state is the previous point's,
// or an older one between checkpoints); -1 kills it once the CSV header is written, before any
// point. Nothing is cleaned up, as with a real kill. Unset (or not a number), runs are not
// affected.
int kill_after_row() {
  const char* value = std::getenv("KIRCHHOFF_TEST_KILL_AFTER_ROW");
  if (!value || !*value) return -2;
  char* end = nullptr;
  const long k = std::strtol(value, &end, 10);
  return *end == '\0' && k >= -1 ? static_cast<int>(k) : -2;
}

// The terminal: one line updated in place on a terminal, plain lines (every 10th point and every
// special point) otherwise; the run's notes on lines of their own; the kill hook. Comes after the
// CSV in the sinks, so that a killed run has its row written.
class TerminalSink : public ContinueSink {
 public:
  explicit TerminalSink(std::string parameter)
      : parameter_(std::move(parameter)), tty_(isatty(STDERR_FILENO)), kill_after_(kill_after_row()) {}
  void begin(const std::string&, const std::vector<std::string>&, int) override {
    if (kill_after_ == -1) kill(getpid(), SIGKILL);
  }
  void point(const RunPoint& rp) override {
    if (rp.row == kill_after_) kill(getpid(), SIGKILL);
    const ContinuationPoint& p = *rp.point;
    std::ostringstream line;
    line << "branch " << rp.branch << "  point " << rp.row << "  " << parameter_ << " = " << std::setprecision(10)
         << p.parameter << "  step " << std::setprecision(3) << p.step;
    if (p.type != PointType::Regular && p.type != PointType::Start) line << "  [" << to_string(p.type) << "]";
    if (!H_is_flat(p)) line << "  [H not flat]";
    if (p.stability_index) line << (*p.stability_index == 0 ? "  stable" : "  index " + std::to_string(*p.stability_index));
    if (tty_) {
      std::cerr << "\r" << line.str() << "\033[K" << std::flush;
      open_line_ = true;
    } else if (rp.row % 10 == 0 || p.type != PointType::Regular || !H_is_flat(p)) {
      std::cerr << line.str() << "\n";
    }
  }
  void note(const std::string& line) override {
    done();
    std::cerr << line << "\n";
  }
  void finish(const RunState*) override { done(); }
  // Ends the line updated in place.
  void done() {
    if (open_line_) std::cerr << "\n";
    open_line_ = false;
  }

 private:
  std::string parameter_;
  bool tty_;
  bool open_line_ = false;
  int kill_after_;
};

std::vector<ContinuationEvent> parse_events(const std::vector<std::string>& texts, bool stop) {
  std::vector<ContinuationEvent> out;
  for (const auto& t : texts) {
    const auto [name, value] = parse_override(t);
    out.push_back({name, value, stop, ""});
  }
  return out;
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

// What the run's end says on the terminal, and the exit status.
int report_end(const ContinueArguments& args, const ContinueRunResult& r) {
  if (args.deflate) {
    std::cerr << r.equilibria << " equilibria at the start (" << r.search_stopped_because << ")\n";
    for (const auto& b : r.branches) {
      std::cerr << "branch " << b.rank << " stopped: " << to_string(b.reason)
                << (b.message.empty() ? "" : " (" + b.message + ")") << "\n";
      for (const auto& line : b.contact_changes) std::cerr << "  contact: " << line << "\n";
    }
    std::cerr << r.points << " points on " << r.branches.size() << " branches in " << args.out_path << "\n";
    return r.ok ? kExitOk : kExitNotConverged;
  }
  for (const auto& line : r.contact_changes) std::cerr << "contact: " << line << "\n";
  if (r.switch_requested && !r.switched && r.reason != StopReason::TimeLimit) {
    std::cerr << "error: " << r.message << "\n";
    return kExitNotConverged;
  }
  std::cerr << "stopped: " << r.status << (r.message.empty() ? "" : " (" + r.message + ")") << "; " << r.points
            << " points";
  if (!r.with_contacts) std::cerr << " (last on branch " << r.last_branch << ")";
  std::cerr << " in " << args.out_path << "\n";
  if (!r.with_contacts) {
    if (r.refused_steps > 0) std::cerr << r.refused_steps << " steps refused and retried shorter\n";
    if (r.reason == StopReason::TimeLimit) std::cerr << "the run can go on with --resume\n";
  }
  return r.ok ? kExitOk : kExitNotConverged;
}

}  // namespace

int run_continue(const ContinueArguments& args) {
  const fs::path csv(args.out_path), state_path(args.out_path + ".state.json");
  if (!(args.checkpoint_seconds >= 0 && args.checkpoint_seconds <= 1e6)) {
    std::cerr << "error: --checkpoint must be in [0, 1e6] seconds\n";
    return kExitBadInput;
  }
  ContinueRequest request;
  request.parameter = args.parameter;
  if (args.has_to) request.target = args.to;
  request.direction = args.direction;
  request.initial_step = args.step;
  request.min_step = args.min_step;
  request.max_step = args.max_step;
  request.max_points = args.max_points;
  request.samples = args.samples;
  request.detect_branch_points = !args.no_branch_points;
  request.compute_stability = !args.no_stability;
  request.switch_at_bp = args.switch_at_bp;
  request.switch_side = args.switch_side;
  request.max_seconds = args.max_seconds;
  request.phase_condition = args.phase_condition;
  request.deflate = args.deflate;
  request.deflate_max = args.deflate_max;
  request.seed = args.seed;
  RunPlanInputs inputs;
  inputs.case_path = args.case_path;
  inputs.phase_condition = args.phase_condition;
  inputs.resume = args.resume;
  inputs.state_path = state_path;
  inputs.csv_path = csv;
  inputs.start_from = args.start_from;
  inputs.start_param = args.start_param;
  RunPlan plan;
  try {
    inputs.overrides = parse_overrides(args.case_path, args.overrides);
    inputs.solver = parse_solver_overrides(args.solver);
    request.events = parse_events(args.stop_events, true);
    for (auto& e : parse_events(args.record_events, false)) request.events.push_back(e);
    plan = plan_run(inputs, &request);
    for (const auto& note : plan.notes) std::cerr << note << "\n";
    if (plan.start) print_start(*plan.start, plan.c, args.parameter);
  } catch (const std::invalid_argument& e) {  // CaseError, a bad NAME=VALUE, a state file refused
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::runtime_error& e) {  // a state file that cannot be read
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  const Case& c = plan.c;

  BranchCsvSink branch_csv(csv);
  TerminalSink terminal(args.parameter);
  StateFileSink state_file(state_path, std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                           std::chrono::duration<double>(args.checkpoint_seconds)));
  std::vector<ContinueSink*> sinks = {&branch_csv, &terminal};
  if (!args.deflate) sinks.push_back(&state_file);  // a deflated run is not resumable
  std::optional<ProfileSink> profiles;
  try {
    if (!args.profiles_dir.empty()) sinks.push_back(&profiles.emplace(c, args.parameter, args.profiles_dir, args.samples));
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  ContinueRunResult result;
  try {
    result = continue_case(c, request, sinks);
  } catch (const CaseError& e) {  // a start point of another problem, outputs that cannot be written
    terminal.done();
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {  // the seed's Ipopt did not converge, a march that threw
    terminal.done();
    std::cerr << "error: " << e.what() << "\n";
    return kExitNotConverged;
  }
  return report_end(args, result);
}

}  // namespace kirchhoff::cli
